#include "algorithms/shape/image_gradients.hpp"

#include <cmath>
#include <stdexcept>
#include <type_traits>

#include <opencv2/core/hal/intrin.hpp>
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

// The same as the scalar loop below (the same float operations, correctly rounded in both), 16
// pixels at a time; returns the number of pixels done.
int normaliseSimd(const short* px, const short* py, int n, float min2, cv::Vec2b* o) {
  const cv::v_float32x4 lowest = cv::v_setall_f32(min2), scale = cv::v_setall_f32(127.0f);
  const cv::v_float32x4 zero = cv::v_setzero_f32();
  auto rounded = [&](const cv::v_int32x4& ia, const cv::v_int32x4& ib, cv::v_int32x4& ra,
                     cv::v_int32x4& rb) {
    const cv::v_float32x4 a = cv::v_cvt_f32(ia), b = cv::v_cvt_f32(ib);
    const cv::v_float32x4 m2 = a * a + b * b;
    const cv::v_float32x4 inv = cv::v_select(m2 >= lowest, scale / cv::v_sqrt(m2), zero);
    ra = cv::v_round(a * inv);
    rb = cv::v_round(b * inv);
  };
  int x = 0;
  for (; x + 16 <= n; x += 16) {
    cv::v_int16x8 outA[2], outB[2];
    for (int h = 0; h < 2; ++h) {
      cv::v_int32x4 a0, a1, b0, b1, ra0, ra1, rb0, rb1;
      cv::v_expand(cv::v_load(px + x + 8 * h), a0, a1);
      cv::v_expand(cv::v_load(py + x + 8 * h), b0, b1);
      rounded(a0, b0, ra0, rb0);
      rounded(a1, b1, ra1, rb1);
      outA[h] = cv::v_pack(ra0, ra1);
      outB[h] = cv::v_pack(rb0, rb1);
    }
    cv::v_store_interleave(reinterpret_cast<schar*>(o + x), cv::v_pack(outA[0], outA[1]),
                           cv::v_pack(outB[0], outB[1]));
  }
  return x;
}

// Raw Sobel responses (8 x grey levels per pixel) -> directions scaled by 127.
template <typename T>
void normalise(const cv::Mat& gx, const cv::Mat& gy, float min2, cv::Mat& out) {
  for (int y = 0; y < gx.rows; ++y) {
    const T* px = gx.ptr<T>(y);
    const T* py = gy.ptr<T>(y);
    auto* o = out.ptr<cv::Vec2b>(y);
    int x = 0;
    if constexpr (std::is_same_v<T, short>) x = normaliseSimd(px, py, gx.cols, min2, o);
    for (; x < gx.cols; ++x) {
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
