#include "tests/support/scene/plane_scene.hpp"

#include <algorithm>
#include <cmath>
#include <iterator>
#include <numbers>
#include <random>
#include <stdexcept>

#include <opencv2/calib3d.hpp>
#include <opencv2/imgproc.hpp>

namespace facet::scene {
namespace {

// A chord of length L on a curve of radius R is off it by L^2 / (8 R): 0.2 px chords leave
// 1e-4 px on a 50 px disc and far less on the gently bent straight edges.
constexpr double kChordPx = 0.2;

// A pixel position on the grid `scale` times finer (pixel centres at integers on both grids).
cv::Point2d onGrid(cv::Point2d p, double scale) {
  return {(p.x + 0.5) * scale - 0.5, (p.y + 0.5) * scale - 0.5};
}

cv::Rect2d boundsOf(const std::vector<cv::Point2d>& poly) {
  double x0 = 1e300, y0 = 1e300, x1 = -1e300, y1 = -1e300;
  for (const auto& p : poly) {
    x0 = std::min(x0, p.x), y0 = std::min(y0, p.y);
    x1 = std::max(x1, p.x), y1 = std::max(y1, p.y);
  }
  return {x0, y0, x1 - x0, y1 - y0};
}

// The cells an outline can touch, with a cell to spare on each side.
cv::Rect cellsUnder(const std::vector<cv::Point2d>& outline) {
  const cv::Rect2d b = boundsOf(outline);
  return {static_cast<int>(std::floor(b.x)) - 1, static_cast<int>(std::floor(b.y)) - 1,
          static_cast<int>(std::ceil(b.width)) + 3, static_cast<int>(std::ceil(b.height)) + 3};
}

// Adds w times the exact overlap of [x0, x1] with each cell [i-0.5, i+0.5] of a row.
void addSpan(double* row, int width, double x0, double x1, double w) {
  x0 = std::max(x0, -0.5);
  x1 = std::min(x1, width - 0.5);
  if (x1 <= x0) return;
  const int i0 = std::clamp(static_cast<int>(std::floor(x0 + 0.5)), 0, width - 1);
  const int i1 = std::clamp(static_cast<int>(std::floor(x1 + 0.5)), 0, width - 1);
  if (i0 == i1) {
    row[i0] += w * (x1 - x0);
    return;
  }
  row[i0] += w * (i0 + 0.5 - x0);
  for (int i = i0 + 1; i < i1; ++i) row[i] += w;
  row[i1] += w * (x1 - (i1 - 0.5));
}

}  // namespace

cv::Point2d LensCamera::distortNormalised(cv::Point2d n) const {
  const double x = n.x, y = n.y, r2 = x * x + y * y;
  const double radial = 1 + k1 * r2 + k2 * r2 * r2 + k3 * r2 * r2 * r2;
  return {x * radial + 2 * p1 * x * y + p2 * (r2 + 2 * x * x),
          y * radial + p1 * (r2 + 2 * y * y) + 2 * p2 * x * y};
}

cv::Point2d LensCamera::project(const cv::Vec3d& c) const {
  if (c[2] <= 0) throw std::invalid_argument("plane scene: a point lies behind the camera");
  const cv::Point2d d = distortNormalised({c[0] / c[2], c[1] / c[2]});
  return {fx * d.x + cx, fy * d.y + cy};
}

cv::Mat LensCamera::distortion() const {
  return (cv::Mat_<double>(1, 5) << k1, k2, p1, p2, k3);
}

cv::Vec3d PlanePlacement::toCamera(cv::Point2d q, double z) const {
  return rotation * cv::Vec3d(q.x, q.y, z) + translationMm;
}

PlanePlacement lookAtPlane(cv::Point2d target, double distanceMm, double tiltDeg,
                           double tiltAxisDeg, double spinDeg, const LensCamera& camera,
                           cv::Point2d shiftPx) {
  const double deg = std::numbers::pi / 180;
  cv::Mat spin, tilt;
  cv::Rodrigues(cv::Vec3d(0, 0, spinDeg * deg), spin);
  cv::Rodrigues(
      cv::Vec3d(std::cos(tiltAxisDeg * deg), std::sin(tiltAxisDeg * deg), 0) * (tiltDeg * deg),
      tilt);
  PlanePlacement p;
  p.rotation = cv::Matx33d(cv::Mat(tilt * spin));
  cv::Vec3d ray(shiftPx.x / camera.fx, shiftPx.y / camera.fy, 1.0);
  ray /= cv::norm(ray);
  p.translationMm = distanceMm * ray - p.rotation * cv::Vec3d(target.x, target.y, 0);
  return p;
}

void PlaneScene::addPolygon(std::vector<cv::Point2d> mm, double grey) {
  shapes.push_back({std::move(mm), {}, {}, 0.0, grey});
}

void PlaneScene::addPolygons(std::vector<std::vector<cv::Point2d>> mm, double grey) {
  if (mm.empty()) return;
  for (const auto& polygon : mm)
    if (polygon.empty()) throw std::invalid_argument("plane scene: an empty polygon");
  PlaneShape shape{std::move(mm.front()), {}, {}, 0.0, grey};
  shape.morePolygons.assign(std::make_move_iterator(mm.begin() + 1),
                            std::make_move_iterator(mm.end()));
  shapes.push_back(std::move(shape));
}

void PlaneScene::addDisc(cv::Point2d centreMm, double radiusMm, double grey) {
  shapes.push_back({{}, {}, centreMm, radiusMm, grey});
}

cv::Point2d PlaneScene::imageOf(cv::Point2d q) const {
  return camera.project(placement.toCamera(q));
}

std::vector<cv::Point2d> projectOutline(const PlaneScene& scene, const PlaneShape& shape,
                                        double scale) {
  if (!shape.polygon.empty()) return projectPolygon(scene, shape.polygon, scale);
  const double circumferencePx =
      2 * std::numbers::pi *
      cv::norm(scene.imageOf(shape.centre + cv::Point2d(shape.radius, 0)) -
               scene.imageOf(shape.centre)) *
      1.5;
  const int n = std::max(64, static_cast<int>(std::ceil(circumferencePx / kChordPx)));
  std::vector<cv::Point2d> out;
  for (int i = 0; i < n; ++i) {
    const double a = 2 * std::numbers::pi * i / n;
    out.push_back(onGrid(
        scene.imageOf(shape.centre + shape.radius * cv::Point2d(std::cos(a), std::sin(a))), scale));
  }
  return out;
}

std::vector<cv::Point2d> projectPolygon(const PlaneScene& scene, const std::vector<cv::Point2d>& v,
                                        double scale) {
  std::vector<cv::Point2d> out;
  for (std::size_t i = 0; i < v.size(); ++i) {
    const cv::Point2d a = v[i], b = v[(i + 1) % v.size()];
    const double lengthPx = cv::norm(scene.imageOf(b) - scene.imageOf(a)) * 1.2;
    const int n = std::max(1, static_cast<int>(std::ceil(lengthPx / kChordPx)));
    for (int k = 0; k < n; ++k)
      out.push_back(onGrid(scene.imageOf(a + (b - a) * (static_cast<double>(k) / n)), scale));
  }
  return out;
}

cv::Mat polygonCoverage(const std::vector<cv::Point2d>& poly, cv::Size size, int subrows) {
  cv::Mat coverage = cv::Mat::zeros(size, CV_64F);
  const cv::Rect2d box = boundsOf(poly);
  const int r0 = std::max(0, static_cast<int>(std::floor(box.y + 0.5)));
  const int r1 = std::min(size.height - 1, static_cast<int>(std::floor(box.y + box.height + 0.5)));
  if (r1 < r0) return coverage;
  // Edge table: each segment drops its crossings into the sub-scanlines it spans.
  const int lines = (r1 - r0 + 1) * subrows;
  std::vector<std::vector<double>> crossings(static_cast<std::size_t>(lines));
  const double y0 = r0 - 0.5, h = 1.0 / subrows;
  for (std::size_t i = 0, n = poly.size(); i < n; ++i) {
    const cv::Point2d a = poly[i], b = poly[(i + 1) % n];
    if (a.y == b.y) continue;
    const double lo = std::min(a.y, b.y), hi = std::max(a.y, b.y);
    // Sub-scanline k sits at y0 + (k + 0.5) h; half-open rule: lo <= y < hi.
    const int k0 = std::max(0, static_cast<int>(std::ceil((lo - y0) / h - 0.5)));
    const int k1 = std::min(lines - 1, static_cast<int>(std::ceil((hi - y0) / h - 0.5)) - 1);
    for (int k = k0; k <= k1; ++k) {
      const double y = y0 + (k + 0.5) * h;
      crossings[static_cast<std::size_t>(k)].push_back(a.x + (y - a.y) * (b.x - a.x) / (b.y - a.y));
    }
  }
  for (int k = 0; k < lines; ++k) {
    auto& xs = crossings[static_cast<std::size_t>(k)];
    std::sort(xs.begin(), xs.end());
    double* row = coverage.ptr<double>(r0 + k / subrows);
    for (std::size_t i = 0; i + 1 < xs.size(); i += 2)
      addSpan(row, size.width, xs[i], xs[i + 1], h);
  }
  return coverage;
}

cv::Mat PlaneScene::renderIdeal() const {
  const bool blurred = lensBlurSigma > 0;
  const int f = blurred ? std::max(1, fineFactor) : 1;
  const cv::Size fine(camera.size.width * f, camera.size.height * f);
  const int subrows = std::max(16, 256 / f);
  cv::Mat image(fine, CV_64F, cv::Scalar(background));
  const cv::Rect frame(0, 0, fine.width, fine.height);
  for (const PlaneShape& s : shapes) {
    std::vector<std::vector<cv::Point2d>> outlines{projectOutline(*this, s, f)};
    for (const auto& polygon : s.morePolygons)
      outlines.push_back(projectPolygon(*this, polygon, f));
    std::vector<cv::Rect> boxes;
    cv::Rect box;
    for (const auto& outline : outlines) {
      boxes.push_back(cellsUnder(outline) & frame);
      box |= boxes.back();
    }
    if (box.empty()) continue;
    // Each polygon's coverage over its own cells only: a plate's squares are small beside the
    // plate, whose coverage buffer can be the whole fine grid.
    cv::Mat c = cv::Mat::zeros(box.size(), CV_64F);
    for (std::size_t i = 0; i < outlines.size(); ++i) {
      if (boxes[i].empty()) continue;
      std::vector<cv::Point2d> local;
      local.reserve(outlines[i].size());
      for (const auto& p : outlines[i]) local.push_back(p - cv::Point2d(boxes[i].tl()));
      c(boxes[i] - box.tl()) += polygonCoverage(local, boxes[i].size(), subrows);
    }
    cv::Mat region = image(box);
    const cv::Mat painted = region.mul(1.0 - c) + c * s.grey;  // painter's rule on coverage
    painted.copyTo(region);
  }
  if (!blurred) return image;
  const double sigma = lensBlurSigma * f;
  const int k = 2 * static_cast<int>(std::ceil(4 * sigma)) + 1;
  cv::GaussianBlur(image, image, cv::Size(k, k), sigma, sigma, cv::BORDER_REFLECT);
  cv::Mat pixels;
  cv::resize(image, pixels, camera.size, 0, 0, cv::INTER_AREA);  // the pixel's square average
  return pixels;
}

cv::Mat PlaneScene::render() const {
  cv::Mat image = renderIdeal();
  if (noiseSigma > 0) {
    std::mt19937_64 rng(seed);
    std::normal_distribution<double> n(0.0, noiseSigma);
    for (int r = 0; r < image.rows; ++r) {
      auto* row = image.ptr<double>(r);
      for (int c = 0; c < image.cols; ++c) row[c] += n(rng);
    }
  }
  cv::Mat out;
  image.convertTo(out, CV_8U);
  return out;
}

}  // namespace facet::scene
