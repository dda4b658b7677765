#include "algorithms/edges/canny.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <vector>

#include <opencv2/imgproc.hpp>

namespace facet {
namespace {

// 5x5 Sobel gain: binomial [1 4 6 4 1] sums to 16, the derivative [-1 -2 0 2 1] gives 8 per unit
// slope, so a ramp of one grey level per pixel reads 128.
constexpr double kSobelGain = 128.0;

void requireGreyImage(const cv::Mat& image) {
  if (image.empty()) throw std::invalid_argument("edges: the image is empty");
  if (image.type() != CV_8UC1 && image.type() != CV_16UC1)
    throw std::invalid_argument("edges: expected an 8-bit or 16-bit single-channel image, got " +
                                cv::typeToString(image.type()));
}

// Non-maximum suppression along the image axis nearest to the gradient. Ties are broken towards
// the left/upper pixel so that a plateau of two equal magnitudes yields one pixel.
bool isAxisMaximum(const cv::Mat& gx, const cv::Mat& gy, const cv::Mat& mag, int x, int y) {
  const float m = mag.at<float>(y, x);
  if (std::abs(gx.at<float>(y, x)) >= std::abs(gy.at<float>(y, x)))
    return m > mag.at<float>(y, x - 1) && m >= mag.at<float>(y, x + 1);
  return m > mag.at<float>(y - 1, x) && m >= mag.at<float>(y + 1, x);
}

}  // namespace

EdgeGradient computeEdgeGradient(const cv::Mat& image, cv::Rect area) {
  requireGreyImage(image);
  const cv::Rect full(0, 0, image.cols, image.rows);
  area = area.empty() ? full : (area & full);
  EdgeGradient g;
  g.area = area;
  if (area.empty()) return g;
  // Take two pixels of context around the area so that its border gradients see real data.
  const cv::Rect outer = cv::Rect(area.x - 2, area.y - 2, area.width + 4, area.height + 4) & full;
  const cv::Rect inner(area.x - outer.x, area.y - outer.y, area.width, area.height);
  const cv::Mat src = image(outer);
  const double scale = (image.depth() == CV_16U ? 1.0 / 256.0 : 1.0) / kSobelGain;
  cv::Mat dx, dy;
  if (image.depth() == CV_8U) {
    cv::Sobel(src, dx, CV_16S, 1, 0, 5, 1, 0, cv::BORDER_REPLICATE);
    cv::Sobel(src, dy, CV_16S, 0, 1, 5, 1, 0, cv::BORDER_REPLICATE);
  } else {
    cv::Sobel(src, dx, CV_32F, 1, 0, 5, 1, 0, cv::BORDER_REPLICATE);
    cv::Sobel(src, dy, CV_32F, 0, 1, 5, 1, 0, cv::BORDER_REPLICATE);
  }
  dx(inner).convertTo(g.gx, CV_32F, scale);
  dy(inner).convertTo(g.gy, CV_32F, scale);
  cv::magnitude(g.gx, g.gy, g.magnitude);
  return g;
}

cv::Mat cannyFromGradient(const EdgeGradient& gradient, double low, double high,
                          const cv::Mat& mask, cv::Rect candidates) {
  const cv::Size size = gradient.area.size();
  cv::Mat edges = cv::Mat::zeros(size, CV_8U);
  if (size.empty()) return edges;
  if (!mask.empty() && (mask.size() != size || mask.type() != CV_8UC1))
    throw std::invalid_argument("edges: the mask must be CV_8UC1 of the region's size");
  const cv::Rect inside(1, 1, size.width - 2, size.height - 2);
  candidates = candidates.empty() ? cv::Rect(2, 2, size.width - 4, size.height - 4) & inside
                                  : candidates & inside;
  const auto lowF = static_cast<float>(low);
  const auto highF = static_cast<float>(std::max(low, high));

  // 1 = candidate (local maximum >= low), 2 = accepted edge.
  cv::Mat state = cv::Mat::zeros(size, CV_8U);
  std::vector<cv::Point> stack;
  for (int y = candidates.y; y < candidates.y + candidates.height; ++y) {
    const auto* m = gradient.magnitude.ptr<float>(y);
    const uchar* k = mask.empty() ? nullptr : mask.ptr<uchar>(y);
    auto* s = state.ptr<uchar>(y);
    for (int x = candidates.x; x < candidates.x + candidates.width; ++x) {
      if (m[x] < lowF || (k && !k[x])) continue;
      if (!isAxisMaximum(gradient.gx, gradient.gy, gradient.magnitude, x, y)) continue;
      s[x] = 1;
      if (m[x] >= highF) {
        s[x] = 2;
        stack.emplace_back(x, y);
      }
    }
  }
  // Hysteresis: grow the strong pixels through 8-connected candidates.
  while (!stack.empty()) {
    const cv::Point p = stack.back();
    stack.pop_back();
    for (int dy = -1; dy <= 1; ++dy) {
      auto* s = state.ptr<uchar>(p.y + dy);
      for (int dx = -1; dx <= 1; ++dx) {
        if (s[p.x + dx] == 1) {
          s[p.x + dx] = 2;
          stack.emplace_back(p.x + dx, p.y + dy);
        }
      }
    }
  }
  for (int y = 0; y < size.height; ++y) {
    const auto* s = state.ptr<uchar>(y);
    auto* e = edges.ptr<uchar>(y);
    for (int x = 0; x < size.width; ++x) e[x] = s[x] == 2 ? 255 : 0;
  }
  return edges;
}

cv::Mat cannyEdges(const cv::Mat& image, double low, double high, cv::Rect roi,
                   const cv::Mat& mask) {
  const EdgeGradient g = computeEdgeGradient(image, roi);
  cv::Mat localMask;
  if (!mask.empty()) {
    if (mask.size() != image.size() || mask.type() != CV_8UC1)
      throw std::invalid_argument("edges: the mask must be CV_8UC1 of the image's size");
    localMask = mask(g.area);
  }
  return cannyFromGradient(g, low, high, localMask);
}

}  // namespace facet
