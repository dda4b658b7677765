#pragma once
// Canny edge pixels with hysteresis on 8- and 16-bit images.
//
// The gradient is the 5x5 Sobel derivative (binomial smoothing across, central differences
// along), normalised to grey levels per pixel on the 8-bit scale (16-bit input is divided by
// 256). Non-maximum suppression compares each pixel with its two neighbours along the image axis
// closest to the gradient (left/right when |gx| >= |gy|, otherwise up/down). Comparing along an
// axis rather than along the gradient keeps exactly one pixel per row (steep edges) or per column
// (flat edges): on a 45 degree edge two diagonal neighbours lie within one pixel of the edge
// along the gradient and both would survive direction-quantised suppression.

#include <opencv2/core.hpp>

#include "algorithms/edges/row_runs.hpp"

namespace facet {

struct EdgeGradient {
  cv::Rect area;      // the image area the maps cover (image coordinates)
  cv::Mat gx, gy;     // raw 5x5 Sobel derivatives, x right / y down: CV_16S for 8-bit input,
                      // CV_32F for 16-bit input; multiply by `scale` for grey levels per pixel
  double scale = 1;   // 1/128 for 8-bit, 1/(128*256) for 16-bit input
  cv::Mat magnitude;  // CV_32F, grey levels per pixel (8-bit scale): scale * |(gx, gy)|
};

// Gradient of `image` (CV_8UC1 or CV_16UC1) over `area` (clipped to the image; empty = all).
// Throws std::invalid_argument for any other image type.
EdgeGradient computeEdgeGradient(const cv::Mat& image, cv::Rect area = {});

// The gradient at the pixels of `runs` (image coordinates) and their eight neighbours only, in
// maps covering `area` (clipped to the image): what cannyOnRuns reads. Equal to
// computeEdgeGradient(image, area) at those pixels; the maps' other pixels are left unset. A thin
// region (an annulus) costs its own size instead of its bounding box's.
EdgeGradient computeEdgeGradientOnRuns(const cv::Mat& image, cv::Rect area, const RowRuns& runs);

// Edge pixels (CV_8U, 255 = edge, same size as gradient.area) after non-maximum suppression and
// hysteresis: a pixel whose magnitude is >= low is kept when it is 8-connected through such
// pixels to one whose magnitude is >= high. `mask` (CV_8U, size of gradient.area, may be empty)
// restricts the candidates to its non-zero pixels. Only pixels inside `candidates` (coordinates
// local to gradient.area; empty = the area shrunk by 2 pixels) can be edges; it is always kept
// one pixel away from the area's border, which suppression needs as neighbours.
cv::Mat cannyFromGradient(const EdgeGradient& gradient, double low, double high,
                          const cv::Mat& mask = {}, cv::Rect candidates = {});

// Canny whose candidates are the pixels of `runs` (image coordinates; those less than one pixel
// inside gradient.area are dropped): cannyFromGradient with a mask of exactly these pixels, reading
// only them and their neighbours (a gradient from computeEdgeGradientOnRuns suffices). Result as
// cannyFromGradient's.
cv::Mat cannyOnRuns(const EdgeGradient& gradient, double low, double high, const RowRuns& runs);

// The same as cannyFromGradient(computeEdgeGradient(image, area), ...), computed in strips of
// rows so that no full-size gradient maps are allocated (faster on large images). `mask` and
// `candidates` are relative to `area`, which must lie inside the image.
cv::Mat cannyInStrips(const cv::Mat& image, cv::Rect area, double low, double high,
                      const cv::Mat& mask = {}, cv::Rect candidates = {});

// Convenience: gradient and Canny over `roi` (empty = whole image); result has the ROI's size.
cv::Mat cannyEdges(const cv::Mat& image, double low, double high, cv::Rect roi = {},
                   const cv::Mat& mask = {});

}  // namespace facet
