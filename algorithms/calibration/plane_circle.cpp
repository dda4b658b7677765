#include "algorithms/calibration/plane_circle.hpp"

#include <cmath>
#include <iomanip>
#include <sstream>

#include <Eigen/Dense>
#include <opencv2/imgproc.hpp>

#include "algorithms/circle/circle_fit.hpp"

#include "algorithms/calibration/plane_circle_profile.hpp"
#include "algorithms/calibration/plane_patch.hpp"

namespace facet {

std::optional<PlaneCircle> fitCircle(const std::vector<cv::Point2d>& points) {
  const auto n = static_cast<Eigen::Index>(points.size());
  if (n < 3) return std::nullopt;
  // Kasa's algebraic fit as the start: x^2 + y^2 + D x + E y + F = 0, centred for conditioning.
  cv::Point2d mean(0, 0);
  for (const auto& p : points) mean += p;
  mean /= static_cast<double>(n);
  Eigen::MatrixXd A(n, 3);
  Eigen::VectorXd b(n);
  for (Eigen::Index i = 0; i < n; ++i) {
    const cv::Point2d p = points[static_cast<std::size_t>(i)] - mean;
    A.row(i) << p.x, p.y, 1.0;
    b(i) = -(p.x * p.x + p.y * p.y);
  }
  const Eigen::Vector3d k = A.colPivHouseholderQr().solve(b);
  double cx = -k(0) / 2, cy = -k(1) / 2;
  double r = std::sqrt(std::max(cx * cx + cy * cy - k(2), 0.0));
  if (!std::isfinite(r) || r <= 0) return std::nullopt;
  // Gauss-Newton on the orthogonal distances |p - c| - r (converges in a few steps from Kasa).
  Eigen::MatrixXd J(n, 3);
  Eigen::VectorXd res(n);
  for (int it = 0; it < 20; ++it) {
    for (Eigen::Index i = 0; i < n; ++i) {
      const cv::Point2d p = points[static_cast<std::size_t>(i)] - mean;
      const double dx = p.x - cx, dy = p.y - cy, d = std::hypot(dx, dy);
      if (d <= 0) return std::nullopt;
      J.row(i) << -dx / d, -dy / d, -1.0;
      res(i) = d - r;
    }
    const Eigen::Vector3d step = J.colPivHouseholderQr().solve(-res);
    cx += step(0), cy += step(1), r += step(2);
    if (step.norm() < 1e-12 * std::max(1.0, r)) break;
  }
  if (!std::isfinite(cx) || !std::isfinite(cy) || !std::isfinite(r) || r <= 0) return std::nullopt;
  PlaneCircle c;
  c.centreMm = mean + cv::Point2d(cx, cy);
  c.diameterMm = 2 * r;
  c.rmsMm = std::sqrt(res.squaredNorm() / static_cast<double>(n));
  c.roundnessMm = res.maxCoeff() - res.minCoeff();
  c.points = static_cast<int>(n);
  return c;
}

namespace {

// The curvature bias constant of a measurement's edge points: second-derivative edges on a blurred
// curved rim sit k / r inside it, k = (sigma^2 + 1.2) / 2 for a Gaussian blur sigma
// (circle_measure.hpp), which the grey-value fit measured.
double edgeBiasK(const CircleMeasurement& m) {
  return m.greyRefined ? (m.blur * m.blur + 1.2) / 2 : CircleMeasureParams{}.radiusBiasK;
}

// The circle through a rim's edge points in the plane, each moved out by the bias k / r first.
// Each point mapped through `patch` when there is one (the annulus's, which the grey fit uses),
// else exactly: a big rim has hundreds of points, each an iterative undistortion.
std::optional<PlaneCircle> edgePointCircle(const std::vector<cv::Point2d>& points, double k,
                                           const WorldMapping& mapping,
                                           const PlanePatch* patch = nullptr) {
  // The edge points' own circle in the image, for the outward direction of each point.
  const auto edges = fitCircle(points);
  if (!edges) return std::nullopt;
  // (The grey fit's radius cannot be used directly: it fits a circle to what may be an ellipse in
  // the image.)
  const double shift = k / (edges->diameterMm / 2);
  std::vector<cv::Point2d> plane;
  plane.reserve(points.size());
  for (const auto& p : points) {
    const cv::Point2d radial = p - edges->centreMm;
    const double d = cv::norm(radial);
    const cv::Point2d at = d > 0 ? p + radial * (shift / d) : p;
    const cv::Point2d q = patch ? patch->at(at).mm : mapping.toPlane(at);
    if (!std::isfinite(q.x) || !std::isfinite(q.y)) return std::nullopt;
    plane.push_back(q);
  }
  auto c = fitCircle(plane);
  if (!c) return c;
  // Coverage as CircleMeasure counts it, its gaps in pixels of arc at the plane's scale there.
  const double scale = mapping.mmPerPixelAt(mapping.toImage(c->centreMm));
  std::vector<Eigen::Vector2d> around;
  around.reserve(plane.size());
  for (const auto& q : plane) around.emplace_back(q.x / scale, q.y / scale);
  c->coverageDeg = circle_fit::coverageDeg(
      around,
      {Eigen::Vector2d{c->centreMm.x / scale, c->centreMm.y / scale}, c->diameterMm / 2 / scale});
  return c;
}

}  // namespace

std::optional<PlaneCircle> circleInPlane(const CircleMeasurement& m, const WorldMapping& mapping) {
  if (!m.status.ok() || m.inlierPoints.size() < 3) return std::nullopt;
  return edgePointCircle(m.inlierPoints, edgeBiasK(m), mapping);
}

bool refusedAsImageCircle(const CircleMeasurement& m) {
  return (m.status.cause == CircleFailure::CoverageTooSmall ||
          m.status.cause == CircleFailure::FitTooPoor) &&
         m.inlierPoints.size() >= 3;
}

namespace {

// The mapping over the box of the annulus's edge points, interpolated (plane_patch.hpp): its
// place and derivatives at each of a big rim's thousands of edge points, without an undistortion
// each.
std::optional<PlanePatch> annulusPatch(const CircleMeasurement& m, const WorldMapping& mapping) {
  std::vector<cv::Point2f> at;
  at.reserve(m.annulusEdges.size() + m.inlierPoints.size());
  for (const EdgePoint& e : m.annulusEdges)
    at.emplace_back(static_cast<float>(e.position.x), static_cast<float>(e.position.y));
  for (const cv::Point2d& p : m.inlierPoints)
    at.emplace_back(static_cast<float>(p.x), static_cast<float>(p.y));
  if (at.empty()) return std::nullopt;
  return PlanePatch::over(mapping, cv::boundingRect(at) + cv::Size(2, 2) - cv::Point(1, 1));
}

// The annulus's edge points judged against a circle in the plane: the rim's (within the RANSAC
// threshold of it, gradient along its normal with the rim's polarity) and the strong foreign ones
// (off it by more than a pixel, or across it), as CircleMeasure judges them against its image
// circle. On a rim seen at an angle (an ellipse in the image) the image circle's judgement
// leaves most of the rim out of its 0.5 px band and calls it foreign.
struct JudgedEdges {
  std::vector<cv::Point2d> rim;
  std::vector<EdgePoint> foreign;
};
JudgedEdges judgeEdges(const CircleMeasurement& m, const PlanePatch& patch, cv::Point2d centreMm,
                       double radiusMm) {
  const CircleMeasureParams defaults;
  const double cosTol = std::cos(defaults.directionToleranceDeg * CV_PI / 180.0);
  JudgedEdges judged;
  for (const EdgePoint& e : m.annulusEdges) {
    const PlanePixel p = patch.at(e.position);
    const RimGeometry g = rimGeometry(p.mm - centreMm, p.alongX, p.alongY, radiusMm);
    const double cosA = m.rimSign * e.normal.dot(g.imageNormal);
    if (std::abs(g.distance) <= defaults.ransacThreshold && cosA >= cosTol)
      judged.rim.push_back(e.position);
    else if (e.magnitude >= m.highThreshold && (std::abs(g.distance) > 1.0 || cosA < cosTol))
      judged.foreign.push_back(e);
  }
  return judged;
}

}  // namespace

std::optional<PlaneCircle> circleInPlane(const cv::Mat& image, const CircleMeasurement& m,
                                         const WorldMapping& mapping) {
  if (!m.status.ok() && !refusedAsImageCircle(m)) return std::nullopt;
  const auto patch = annulusPatch(m, mapping);
  if (!patch) return std::nullopt;
  // The edge points are moved out by the bias of a typical blur (circle_measure.hpp's default),
  // not by the blur of the image's own grey fit: they only start the grey fit in the plane, and
  // the circle step does without the image's (below), so that the step and `facet circle
  // --calibration`, which keeps it for its pixel values, measure the same circle.
  const double k = CircleMeasureParams{}.radiusBiasK;
  auto c = edgePointCircle(m.inlierPoints, k, mapping, &*patch);
  if (!c) return c;
  // The rim's points again, about the circle in the plane, and its edge points' circle from them
  // when they are more than the image fit's inliers.
  JudgedEdges edges = judgeEdges(m, *patch, c->centreMm, c->diameterMm / 2);
  if (edges.rim.size() > m.inlierPoints.size()) {
    if (const auto wider = edgePointCircle(edges.rim, k, mapping, &*patch)) {
      c = wider;
      edges = judgeEdges(m, *patch, c->centreMm, c->diameterMm / 2);
    }
  }
  if (const auto fine = fitPlaneCircleProfile(image, mapping, c->centreMm, c->diameterMm / 2,
                                              edges.rim, edges.foreign, m.noiseSigma)) {
    c->centreMm = fine->centreMm;
    c->diameterMm = 2 * fine->radiusMm;
    c->greyRefined = true;
  }
  return c;
}

std::string refusalInPlane(const PlaneCircle& w, const CircleMeasureParams& p,
                           const WorldMapping& mapping) {
  auto number = [](double v) {
    std::ostringstream out;
    out << std::setprecision(4) << v;
    return out.str();
  };
  const double scale = mapping.mmPerPixelAt(p.centre);
  // Each test written as "passes only when", so that a NaN anywhere refuses.
  if (!(w.coverageDeg >= p.minCoverageDeg))
    return "in the plane too, the rim's points cover " + number(w.coverageDeg) +
           " degrees, less than " + number(p.minCoverageDeg);
  if (!(w.rmsMm <= p.maxRms * scale))
    return "in the plane too, the rim's points lie " + number(w.rmsMm / scale) +
           " px RMS off the circle, more than " + number(p.maxRms);
  if (!(std::abs(w.diameterMm / 2 - p.radius * scale) <= p.width * scale &&
        cv::norm(w.centreMm - mapping.toPlane(p.centre)) <= p.width * scale))
    return "in the plane too, the fitted circle leaves the search annulus";
  return {};
}

PlaneCircleVerdict measureCircleInPlane(const cv::Mat& image, const CircleMeasurement& m,
                                        const CircleMeasureParams& params,
                                        const WorldMapping& mapping) {
  PlaneCircleVerdict verdict;
  if (!m.status.ok() && !refusedAsImageCircle(m)) return verdict;
  verdict.judgedInPlane = !m.status.ok();
  verdict.circle = circleInPlane(image, m, mapping);
  // A clipped rim the grey values could not fit in the plane: its edge points alone are off.
  if (verdict.circle && !verdict.circle->greyRefined)
    if (std::string why = clippedRimRefusal(m, image.depth()); !why.empty()) {
      verdict.refusal = std::move(why);
      verdict.circle.reset();
      return verdict;
    }
  if (verdict.circle && verdict.judgedInPlane) {
    verdict.refusal = refusalInPlane(*verdict.circle, params, mapping);
    if (!verdict.refusal.empty()) verdict.circle.reset();
  }
  return verdict;
}

}  // namespace facet
