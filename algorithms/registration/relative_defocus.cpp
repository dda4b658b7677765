#include "algorithms/registration/relative_defocus.hpp"

#include <algorithm>

#include <opencv2/imgproc.hpp>

namespace facet {

namespace {

// The gradient images of a detail measurement, kept across the blur search: a view's worth of
// fresh float images per step (and the page faults of their first touch) cost as much as the
// filtering itself.
struct GradientBuffers {
  cv::Mat gx, gy;
};

double detailOf(const cv::Mat& grey, const cv::Mat& mask, GradientBuffers& g) {
  cv::Sobel(grey, g.gx, CV_32F, 1, 0, 3, 1.0 / 8);
  cv::Sobel(grey, g.gy, CV_32F, 0, 1, 3, 1.0 / 8);
  cv::multiply(g.gx, g.gx, g.gx);
  cv::multiply(g.gy, g.gy, g.gy);
  cv::add(g.gx, g.gy, g.gx);  // the squared gradient
  cv::Scalar mean, sdev;
  cv::meanStdDev(grey, mean, sdev, mask);
  const double variance = sdev[0] * sdev[0];
  return variance > 0 ? cv::mean(g.gx, mask)[0] / variance : 0.0;
}

}  // namespace

double detailOf(const cv::Mat& grey, const cv::Mat& mask) {
  GradientBuffers g;
  return detailOf(grey, mask, g);
}

double relativeDefocus(const cv::Mat& a, const cv::Mat& b, const cv::Mat& mask) {
  // 8 px inside: the gradients read no pixel outside the overlap (a warp's fill value).
  cv::Mat inner;
  cv::erode(mask, inner, cv::Mat(), cv::Point(-1, -1), 8);
  if (cv::countNonZero(inner) < 1000) return 0.0;
  GradientBuffers gradients;
  const double da = detailOf(a, inner, gradients), db = detailOf(b, inner, gradients);
  if (!(da > 0 && db > 0)) return 0.0;
  const bool aSharper = da > db;
  const cv::Mat& sharp = aSharper ? a : b;
  const double target = std::min(da, db), start = std::max(da, db);
  if (start < 1.1 * target) return 0.0;
  // Blurs of growing width until the sharper view holds no more detail than the other; the
  // width is interpolated between the last two, linearly in the detail.
  double below = 0.0, detailBelow = start;
  cv::Mat blurred;
  for (const double sigma : {0.5, 0.75, 1.0, 1.5, 2.0, 3.0, 4.0, 6.0}) {
    cv::GaussianBlur(sharp, blurred, cv::Size(), sigma, sigma, cv::BORDER_REFLECT);
    const double d = detailOf(blurred, inner, gradients);
    if (d <= target) {
      const double t = (detailBelow - target) / std::max(detailBelow - d, 1e-12);
      const double found = below + t * (sigma - below);
      return aSharper ? found : -found;
    }
    below = sigma;
    detailBelow = d;
  }
  return aSharper ? below : -below;
}

}  // namespace facet
