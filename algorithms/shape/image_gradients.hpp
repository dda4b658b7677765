#pragma once
// Grey-value images on the 8-bit scale and their Sobel gradients, as used by both the model's
// training and the search (internal to facet_shape).

#include <opencv2/core.hpp>

namespace facet::shape_detail {

// 8-bit or 16-bit single-channel image -> CV_32F on the 8-bit grey scale (16-bit divided by 256).
cv::Mat toGreyFloat(const cv::Mat& image);

// Sobel derivatives of a CV_32F image in grey levels per pixel (3x3 Sobel divided by 8).
void sobelGradients(const cv::Mat& image, cv::Mat& gx, cv::Mat& gy);

using Direction = cv::Vec<schar, 2>;  // unit gradient direction scaled by 127

// Unit gradient directions of one pyramid level, scaled by 127 (CV_8SC2), zero where the gradient
// is weaker than minContrast so that noise adds nothing to a score. Computed tile by tile on
// demand: the search only looks near its candidates, and large images need few tiles.
class DirectionField {
 public:
  // `grey`: CV_8U (raw grey levels) or CV_32F (8-bit scale).
  DirectionField(cv::Mat grey, double minContrast);
  // Hands its buffers to the thread's next field of the same size (see image_gradients.cpp).
  ~DirectionField();
  DirectionField(const DirectionField&) = default;
  DirectionField(DirectionField&&) = default;
  DirectionField& operator=(const DirectionField&) = default;
  DirectionField& operator=(DirectionField&&) = default;

  // Makes sure every pixel of `region` (clipped to the image) is computed.
  void ensure(cv::Rect region);
  void ensureAll() { ensure({0, 0, grey_.cols, grey_.rows}); }

  [[nodiscard]] const cv::Mat& directions() const { return field_; }
  [[nodiscard]] cv::Size size() const { return grey_.size(); }

 private:
  static constexpr int kTile = 32;
  cv::Mat grey_;
  cv::Mat field_;
  cv::Mat done_;  // CV_8U, one entry per tile
  double minContrast_;
};

}  // namespace facet::shape_detail
