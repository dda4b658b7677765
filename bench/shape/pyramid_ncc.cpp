#include "bench/shape/pyramid_ncc.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>

#include <opencv2/imgproc.hpp>

namespace facet::bench {
namespace {

struct Turned {
  cv::Mat image, mask;
  double centre = 0.0;  // canvas centre, both axes
};

// The template turned by angleDeg about its centre onto a square canvas, with its mask.
Turned turn(const cv::Mat& templ, double angleDeg) {
  const int side = static_cast<int>(std::ceil(std::hypot(templ.cols, templ.rows))) | 1;
  const double cc = (side - 1) / 2.0;
  const cv::Point2f tc((templ.cols - 1) / 2.0f, (templ.rows - 1) / 2.0f);
  cv::Mat m = cv::getRotationMatrix2D(tc, angleDeg, 1.0);
  m.at<double>(0, 2) += cc - tc.x;
  m.at<double>(1, 2) += cc - tc.y;
  Turned t;
  t.centre = cc;
  cv::warpAffine(templ, t.image, m, {side, side}, cv::INTER_LINEAR, cv::BORDER_CONSTANT);
  cv::warpAffine(cv::Mat(templ.size(), CV_8U, cv::Scalar(255)), t.mask, m, {side, side},
                 cv::INTER_NEAREST, cv::BORDER_CONSTANT);
  cv::erode(t.mask, t.mask, cv::Mat());
  return t;
}

// Masked normalised correlation divides by the patch's deviation: on flat image regions it gives
// NaN or values far above 1, which are no match.
void clean(cv::Mat& result) {
  cv::patchNaNs(result, -1.0);
  result.setTo(-1.0, result > 1.0001);
}

struct Hit {
  double x, y, angle, score;  // centre on the level, degrees
};

// Best turned-template score in a window of +-r pixels around (x, y) on one level.
Hit refineAt(const cv::Mat& image, const cv::Mat& templ, Hit h, int r, double angleStep) {
  Hit best = h;
  best.score = -2;
  for (int k = -2; k <= 2; ++k) {
    const double a = h.angle + k * angleStep;
    const Turned t = turn(templ, a);
    const int side = t.image.cols;
    const cv::Rect window(cvRound(h.x - t.centre) - r, cvRound(h.y - t.centre) - r, side + 2 * r,
                          side + 2 * r);
    const cv::Rect inside = window & cv::Rect(0, 0, image.cols, image.rows);
    if (inside.width < side || inside.height < side) continue;
    cv::Mat result;
    cv::matchTemplate(image(inside), t.image, result, cv::TM_CCOEFF_NORMED, t.mask);
    clean(result);
    double mx;
    cv::Point loc;
    cv::minMaxLoc(result, nullptr, &mx, nullptr, &loc);
    if (mx > best.score) {
      best = {inside.x + loc.x + t.centre, inside.y + loc.y + t.centre, a, mx};
      // Parabola through the neighbours for a subpixel position.
      auto at = [&](int dx, int dy) {
        const cv::Point q = loc + cv::Point(dx, dy);
        return cv::Rect(0, 0, result.cols, result.rows).contains(q) ? double(result.at<float>(q))
                                                                    : mx;
      };
      auto vertex = [](double m, double z, double p) {
        const double d = m - 2 * z + p;
        return d < 0 ? std::clamp(0.5 * (m - p) / d, -0.5, 0.5) : 0.0;
      };
      best.x += vertex(at(-1, 0), mx, at(1, 0));
      best.y += vertex(at(0, -1), mx, at(0, 1));
    }
  }
  return best;
}

}  // namespace

std::vector<NccMatch> findByPyramidNcc(const cv::Mat& image, const cv::Mat& templ, int maxMatches,
                                       double minScore) {
  int levels = 1;
  while (levels < 6 && (std::min(templ.cols, templ.rows) >> levels) >= 16) ++levels;
  std::vector<cv::Mat> img{image}, tpl{templ};
  for (int l = 1; l < levels; ++l) {
    cv::Mat a, b;
    cv::pyrDown(img.back(), a);
    cv::pyrDown(tpl.back(), b);
    img.push_back(a);
    tpl.push_back(b);
  }
  const int top = levels - 1;
  auto stepAt = [&](int l) {
    const double radius = std::hypot(tpl[l].cols, tpl[l].rows) / 2.0;
    return std::atan(1.0 / radius) * 180.0 / std::numbers::pi;
  };
  // Top level: every angle, best score and angle per position.
  const double topStep = stepAt(top);
  cv::Mat best, bestAngle;
  double centre = 0.0;
  for (double a = -180.0; a < 180.0; a += topStep) {
    const Turned t = turn(tpl[top], a);
    if (t.image.cols > img[top].cols || t.image.rows > img[top].rows) continue;
    cv::Mat result;
    cv::matchTemplate(img[top], t.image, result, cv::TM_CCOEFF_NORMED, t.mask);
    clean(result);
    if (best.empty()) {
      best = result.clone();
      bestAngle = cv::Mat(result.size(), CV_32F, cv::Scalar(a));
      centre = t.centre;
      continue;
    }
    const cv::Mat better = result > best;
    result.copyTo(best, better);
    bestAngle.setTo(a, better);
  }
  if (best.empty()) return {};
  // Local maxima, best first.
  cv::Mat dilated;
  const int nms = std::max(3, std::min(tpl[top].cols, tpl[top].rows) / 2);
  cv::dilate(best, dilated, cv::getStructuringElement(cv::MORPH_RECT, {nms, nms}));
  std::vector<Hit> hits;
  for (int y = 0; y < best.rows; ++y)
    for (int x = 0; x < best.cols; ++x) {
      const float v = best.at<float>(y, x);
      if (v >= dilated.at<float>(y, x) && v >= minScore - 0.2)
        hits.push_back({x + centre, y + centre, bestAngle.at<float>(y, x), v});
    }
  std::sort(hits.begin(), hits.end(), [](const Hit& a, const Hit& b) { return a.score > b.score; });
  if (static_cast<int>(hits.size()) > 3 * maxMatches) hits.resize(3 * maxMatches);
  std::vector<NccMatch> out;
  for (Hit h : hits) {
    h = refineAt(img[top], tpl[top], h, 1, topStep / 2);
    for (int l = top - 1; l >= 0; --l) {
      h.x *= 2, h.y *= 2;  // cv::pyrDown centres level pixel i on pixel 2i below
      h = refineAt(img[l], tpl[l], h, 2, stepAt(l) / (l == 0 ? 2 : 1));
    }
    if (h.score < minScore) continue;
    bool duplicate = false;
    for (const auto& o : out)
      duplicate |= std::hypot(o.x - h.x, o.y - h.y) < std::min(templ.cols, templ.rows) / 2.0;
    if (!duplicate) out.push_back({h.x, h.y, h.angle, h.score});
  }
  std::sort(out.begin(), out.end(),
            [](const NccMatch& a, const NccMatch& b) { return a.score > b.score; });
  if (static_cast<int>(out.size()) > maxMatches) out.resize(maxMatches);
  return out;
}

}  // namespace facet::bench
