#include "tests/shape/test_photos.hpp"

#include <gtest/gtest.h>

#include <opencv2/imgcodecs.hpp>

namespace facet::testing {

cv::Mat testPhoto(const std::string& file) {
  const std::string path = FACET_TEST_DATA_DIR "/photos/" + file;
  const cv::Mat photo = cv::imread(path, cv::IMREAD_GRAYSCALE);
  if (photo.empty()) ADD_FAILURE() << "missing " << path;
  return photo;
}

}  // namespace facet::testing
