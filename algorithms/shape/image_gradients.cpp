#include "algorithms/shape/image_gradients.hpp"

#include <cmath>
#include <stdexcept>

#include <opencv2/imgproc.hpp>

namespace facet::shape_detail {

cv::Mat toGreyFloat(const cv::Mat& image) {
  if (image.channels() != 1 || (image.depth() != CV_8U && image.depth() != CV_16U))
    throw std::invalid_argument("expected an 8-bit or 16-bit single-channel image");
  cv::Mat grey;
  image.convertTo(grey, CV_32F, image.depth() == CV_16U ? 1.0 / 256.0 : 1.0);
  return grey;
}

void sobelGradients(const cv::Mat& image, cv::Mat& gx, cv::Mat& gy) {
  // The 3x3 Sobel kernel is 8 times the central difference of a [1 2 1]-smoothed image.
  cv::Sobel(image, gx, CV_32F, 1, 0, 3, 1.0 / 8.0, 0.0, cv::BORDER_REPLICATE);
  cv::Sobel(image, gy, CV_32F, 0, 1, 3, 1.0 / 8.0, 0.0, cv::BORDER_REPLICATE);
}

namespace {

// Raw Sobel responses (8 x grey levels per pixel) -> directions scaled by 127.
template <typename T>
void normalise(const cv::Mat& gx, const cv::Mat& gy, float min2, cv::Mat& out) {
  for (int y = 0; y < gx.rows; ++y) {
    const T* px = gx.ptr<T>(y);
    const T* py = gy.ptr<T>(y);
    auto* o = out.ptr<cv::Vec2b>(y);
    for (int x = 0; x < gx.cols; ++x) {
      const float a = static_cast<float>(px[x]), b = static_cast<float>(py[x]);
      const float m2 = a * a + b * b;
      const float inv = m2 >= min2 ? 127.0f / std::sqrt(m2) : 0.0f;
      // cvRound: an inlined conversion instruction (std::lround is a library call per value).
      o[x] = {static_cast<uchar>(static_cast<signed char>(cvRound(a * inv))),
              static_cast<uchar>(static_cast<signed char>(cvRound(b * inv)))};
    }
  }
}

}  // namespace

DirectionField::DirectionField(cv::Mat grey, double minContrast)
    : grey_(std::move(grey)),
      field_(grey_.size(), CV_8SC2, cv::Scalar(0, 0)),
      done_((grey_.rows + kTile - 1) / kTile, (grey_.cols + kTile - 1) / kTile, CV_8U,
            cv::Scalar(0)),
      minContrast_(std::max(minContrast, 1e-3)) {}

void DirectionField::ensure(cv::Rect region) {
  region &= cv::Rect(0, 0, grey_.cols, grey_.rows);
  if (region.empty()) return;
  const int tx0 = region.x / kTile, tx1 = (region.x + region.width - 1) / kTile;
  const int ty0 = region.y / kTile, ty1 = (region.y + region.height - 1) / kTile;
  // Rows of missing tiles are computed as runs, so that Sobel sees long rows.
  for (int ty = ty0; ty <= ty1; ++ty) {
    for (int tx = tx0; tx <= tx1;) {
      if (done_.at<uchar>(ty, tx)) {
        ++tx;
        continue;
      }
      int end = tx;
      while (end <= tx1 && !done_.at<uchar>(ty, end)) done_.at<uchar>(ty, end++) = 1;
      const cv::Rect run = cv::Rect(tx * kTile, ty * kTile, (end - tx) * kTile, kTile) &
                           cv::Rect(0, 0, grey_.cols, grey_.rows);
      // Sobel on a view reads the real neighbours outside the run (replicated at the image edge),
      // so tiles agree with a whole-image computation.
      cv::Mat gx, gy;
      cv::Mat out = field_(run);
      if (grey_.depth() == CV_8U) {
        cv::Sobel(grey_(run), gx, CV_16S, 1, 0, 3, 1.0, 0.0, cv::BORDER_REPLICATE);
        cv::Sobel(grey_(run), gy, CV_16S, 0, 1, 3, 1.0, 0.0, cv::BORDER_REPLICATE);
        normalise<short>(gx, gy, static_cast<float>(64.0 * minContrast_ * minContrast_), out);
      } else {
        cv::Sobel(grey_(run), gx, CV_32F, 1, 0, 3, 1.0, 0.0, cv::BORDER_REPLICATE);
        cv::Sobel(grey_(run), gy, CV_32F, 0, 1, 3, 1.0, 0.0, cv::BORDER_REPLICATE);
        normalise<float>(gx, gy, static_cast<float>(64.0 * minContrast_ * minContrast_), out);
      }
      tx = end;
    }
  }
}

}  // namespace facet::shape_detail
