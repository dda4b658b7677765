// zeroedMat: all zero whether its block is fresh from the system or one the process used before.
#include <gtest/gtest.h>

#include <vector>

#include "algorithms/shape/zeroed_mat.hpp"

namespace facet {
namespace {

TEST(ZeroedMat, IsAllZeroAlsoWhereAFreedBufferWasWritten) {
  for (const cv::Size size : {cv::Size(64, 48), cv::Size(1280, 1024), cv::Size(4096, 3000)}) {
    for (int round = 0; round < 3; ++round) {
      cv::Mat m = shape_detail::zeroedMat(size, CV_8SC2);
      ASSERT_EQ(m.size(), size);
      ASSERT_EQ(m.type(), CV_8SC2);
      ASSERT_TRUE(m.isContinuous());
      EXPECT_EQ(cv::countNonZero(m.reshape(1)), 0) << size << " round " << round;
      m.setTo(cv::Scalar::all(-7));  // freed written: the next round may get this block back
    }
  }
  // Shared like any Mat: a copy keeps the buffer after the original is gone.
  cv::Mat copy;
  {
    cv::Mat m = shape_detail::zeroedMat({100, 10}, CV_32S);
    m.at<int>(3, 4) = 42;
    copy = m;
  }
  EXPECT_EQ(copy.at<int>(3, 4), 42);
}

}  // namespace
}  // namespace facet
