#include "algorithms/circle/circle_measure.hpp"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <numbers>

#include <Eigen/Dense>
#include <opencv2/imgproc.hpp>

#include "algorithms/circle/annulus_edges.hpp"
#include "algorithms/circle/circle_fit.hpp"
#include "algorithms/circle/circle_profile_fit.hpp"
#include "algorithms/circle/rim_band.hpp"
#include "algorithms/circle/rim_ellipse.hpp"
#include "algorithms/geometry/ransac.hpp"

namespace facet {
namespace {

constexpr double kPi = std::numbers::pi;
constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
// Largest angle between an edge point's gradient and the radial of a RANSAC hypothesis through
// it, degrees. Facet normals of a rim are radial within a few degrees even at 15 grey levels of
// contrast (noise 2); unlike the test against the coarse centre, this one knows the circle.
constexpr double kHypothesisToleranceDeg = 12.0;
// The F statistic beyond which an ellipse explains a rim's points better than a circle: twice
// the value independent points (2 and n - 5 degrees of freedom) exceed once in a million
// measurements, since edge points a pixel apart share most of their 5x5 Facet windows and clutter
// near a rim leaves residuals with structure of their own (at 13.8, round rims of r = 10 px with
// clutter blobs and a ramp took an ellipse in 6 scenes of 60; at 27.6 in 1). The same limit
// screens the circle's residuals' second harmonic (chi-square, 2 degrees of freedom).
constexpr double kEllipseF = 27.6;
// The smallest ratio of an elliptic rim's axes measured as one: a circle viewed 60 degrees
// from square on. A flatter rim is refused (on a calibrated station the plane judges it).
constexpr double kMinAxesRatio = 0.5;
// The least angle an elliptic rim's points must cover, degrees. On a rim with a sector missing
// an ellipse's stretch and its centre trade off, and bumps of clutter within the inlier band
// lend its two extra parameters a significant fit: on bench_circle's hard scenes (30% of the rim
// occluded, blobs near it) ellipses with axes 5% apart passed the F test on round rims of
// r = 10 px and moved their centres by up to 0.5 px. On a nearly whole rim the second harmonic
// is all but independent of the centre.
constexpr double kMinEllipseCoverageDeg = 300.0;
// The second harmonic's chi-square (2 degrees of freedom) in the grey-value fit beyond which the
// rim is not round (fitRimGreyValues): chance alone exceeds it once in a million measurements.
constexpr double kGreyEllipseChiSquare = 27.6;
// How far from round (a Wald test, chi-square with 2 degrees of freedom) the grey values must
// fit the ellipse of a partly hidden rim that the edge points found but could not accept, when
// a circle's grey fit failed there: twice the limit above, since that ellipse's sectors can hold
// clutter the grey fit's screens let pass. On bench_elliptic_rims' round rims of r = 10 px (30%
// hidden, clutter blobs beside the rim) such ellipses reached 27; rims of axes 0.9 apart scored
// 300 and more.
constexpr double kPartialEllipseChiSquare = 55.2;
// An ellipse's shape whose last grey-value step is still this far from zero (chi-square, 2
// degrees of freedom: four standard deviations) has not converged: the rim is refused.
constexpr double kUnsettledShapeChiSquare = 16.0;
// The band about the rim whose pixels at the sensor's limits tell a clipped rim, px: the blurred
// step's reach at a blur of 1 px.
constexpr double kClippedBand = 3.0;

using circle_fit::Circle;
using circle_fit::circleThrough;
using circle_fit::coverageDeg;
using circle_fit::fitGeometric;
using circle_fit::residual;
using circle_fit::robustWeight;

// `m` marked failed and moved out (every caller returns it): a measurement carries the annulus's
// edge points, which a copy would duplicate.
CircleMeasurement failed(CircleMeasurement& m, CircleFailure f, std::string message) {
  m.status = Status<CircleFailure>::failed(f, std::move(message));
  m.centre = {kNaN, kNaN};
  m.radius = m.diameter = kNaN;
  return std::move(m);
}

// A number for a message: "600" or "0.0123", not std::to_string's "600.000000".
std::string readable(double value) {
  return cv::format("%.6g", value);
}

std::string checkParams(const cv::Mat& image, const CircleMeasureParams& p) {
  if (image.empty()) return "the image is empty";
  if (image.channels() != 1 || (image.depth() != CV_8U && image.depth() != CV_16U))
    return "the image must be 8-bit or 16-bit single-channel (got type " +
           std::to_string(image.type()) + ")";
  if (!std::isfinite(p.centre.x) || !std::isfinite(p.centre.y))
    return "the expected centre is not finite";
  if (!(p.radius > 0.0) || !std::isfinite(p.radius))
    return "the nominal radius must be positive (got " + readable(p.radius) + ")";
  if (!(p.width > 0.0) || !std::isfinite(p.width))
    return "the search width must be positive (got " + readable(p.width) + ")";
  if (p.radius + p.width > 1e5)
    return "the annulus (radius + width = " + readable(p.radius + p.width) +
           " px) is larger than any image";
  if (std::abs(p.centre.x) > 1e7 || std::abs(p.centre.y) > 1e7)
    return "the expected centre lies absurdly far outside the image";
  if (!(p.directionToleranceDeg > 0.0 && p.directionToleranceDeg <= 90.0))
    return "the direction tolerance must be in (0, 90] degrees";
  if (!(p.ransacThreshold > 0.0)) return "the RANSAC threshold must be positive";
  if (p.minInliers < 3) return "min inliers must be at least 3";
  if (!(p.minCoverageDeg >= 0.0 && p.minCoverageDeg <= 360.0))
    return "min coverage must be in [0, 360] degrees";
  if (!(p.maxRms > 0.0)) return "max rms must be positive";
  if (p.cannyLow && p.cannyHigh && *p.cannyLow > *p.cannyHigh)
    return "the low Canny threshold exceeds the high one";
  return {};
}

// Geometric fit of the rim: twice, collect the points within the RANSAC threshold of the current
// circle and fit them (plain least squares, then reweighted). `in` receives the final inliers.
// When the second round collects the same points as the first, its fit would start from the
// first one's result and converge to it again: it is skipped.
std::optional<Circle> fitRim(const std::vector<Eigen::Vector2d>& pts, Circle circle,
                             const CircleMeasureParams& params, std::vector<Eigen::Vector2d>& in) {
  std::vector<double> w;
  std::vector<std::uint8_t> taken, takenBefore;
  in.reserve(pts.size());
  for (int round = 0; round < 2; ++round) {
    in.clear();
    taken.assign(pts.size(), 0);
    for (std::size_t i = 0; i < pts.size(); ++i)
      if (std::abs(residual(circle, pts[i])) <= params.ransacThreshold) {
        in.push_back(pts[i]);
        taken[i] = 1;
      }
    if (static_cast<int>(in.size()) < params.minInliers || taken == takenBefore) break;
    std::swap(taken, takenBefore);
    w.assign(in.size(), 1.0);
    const int irls = params.robustWeight == CircleRobustWeight::None ? 1 : 2;
    for (int k = 0; k < irls; ++k) {
      if (k > 0) {
        std::vector<double> a;
        a.reserve(in.size());
        for (const auto& p : in) a.push_back(std::abs(residual(circle, p)));
        const double sigma = std::max(1.4826 * rim_band::medianOf(std::move(a)), 0.01);
        for (std::size_t i = 0; i < in.size(); ++i)
          w[i] = robustWeight(params.robustWeight, residual(circle, in[i]), sigma);
      }
      auto refined = fitGeometric(in, w, circle);
      if (!refined) return std::nullopt;
      circle = *refined;
    }
  }
  return circle;
}

// Angular runs of inliers (split where neighbours are more than maxGap apart), as index lists
// into `in`, around the circle's centre. `angles` receives the inliers' polar angles, sorted.
std::vector<std::vector<std::size_t>> inlierArcs(const std::vector<Eigen::Vector2d>& in,
                                                 const Circle& c, double maxGap,
                                                 std::vector<double>& angles) {
  std::vector<std::pair<double, std::size_t>> a;
  a.reserve(in.size());
  for (std::size_t i = 0; i < in.size(); ++i)
    a.emplace_back(std::atan2(in[i].y() - c.centre.y(), in[i].x() - c.centre.x()), i);
  // By angle, then index: the pairs' own order, without their three-way comparison (which cost
  // as much as the rest of the sort).
  std::sort(a.begin(), a.end(), [](const auto& l, const auto& r) {
    return l.first < r.first || (l.first == r.first && l.second < r.second);
  });
  angles.clear();
  angles.reserve(a.size());
  for (const auto& [angle, i] : a) angles.push_back(angle);
  std::vector<std::vector<std::size_t>> arcs;
  for (std::size_t k = 0; k < a.size(); ++k) {
    if (k == 0 || a[k].first - a[k - 1].first > maxGap) arcs.emplace_back();
    arcs.back().push_back(a[k].second);
  }
  // The run through +-180 degrees is one arc.
  if (arcs.size() > 1 && a.front().first + 2.0 * kPi - a.back().first <= maxGap) {
    arcs.front().insert(arcs.front().end(), arcs.back().begin(), arcs.back().end());
    arcs.pop_back();
  }
  return arcs;
}

// A short run of inliers that the rest of the rim does not predict: the straight border of an
// occluder or a clutter edge that happens to lie within the RANSAC threshold of a circle pulled
// towards it (at r = 10 px, a light occluder's far side 2 px outside the rim lent a circle 1 px
// off five of its points). Each run holding under a third of the inliers is judged against a
// plain fit of the others, when those cover at least the minimum coverage: a real piece of the
// rim lies on that circle within its noise, a foreign one off it by more than the RANSAC
// threshold. Returns the points to drop (empty when every run belongs); `angles` receives the
// inliers' polar angles around `c`, sorted.
std::vector<Eigen::Vector2d> strayArc(const std::vector<Eigen::Vector2d>& in, const Circle& c,
                                      const CircleMeasureParams& params,
                                      std::vector<double>& angles) {
  const double maxGap = std::max(3.0 / std::max(c.radius, 1e-6), 2.0 * kPi / 180.0);
  const auto arcs = inlierArcs(in, c, maxGap, angles);
  if (arcs.size() < 2) return {};
  double worst = 0.0;
  std::vector<Eigen::Vector2d> stray;
  for (const auto& arc : arcs) {
    if (3 * arc.size() >= in.size()) continue;
    std::vector<Eigen::Vector2d> rest, own;
    rest.reserve(in.size());
    own.reserve(arc.size());
    std::vector<std::uint8_t> mine(in.size(), 0);
    for (std::size_t i : arc) mine[i] = 1;
    for (std::size_t i = 0; i < in.size(); ++i) (mine[i] ? own : rest).push_back(in[i]);
    if (static_cast<int>(rest.size()) < params.minInliers) continue;
    const auto others = fitGeometric(rest, std::vector<double>(rest.size(), 1.0), c);
    if (!others || coverageDeg(rest, *others) < params.minCoverageDeg) continue;
    std::vector<double> r;
    for (const auto& p : own) r.push_back(residual(*others, p));
    const double off = std::abs(rim_band::medianOf(std::move(r)));
    if (off > params.ransacThreshold && off > worst) {
      worst = off;
      stray = std::move(own);
    }
  }
  return stray;
}

// Strong edge points that are not the rim: off the circle (the ellipse, when the rim is one) or
// not along its normal with the rim's polarity (rimSign +1: gradient outwards). Weak ones (below
// the high threshold) are mostly noise and must not punch holes into the grey-value fit.
std::vector<EdgePoint> foreignEdges(const std::vector<EdgePoint>& edges, double highThreshold,
                                    const Circle& circle,
                                    const std::optional<rim_ellipse::Ellipse>& ellipse, int rimSign,
                                    double cosTol) {
  std::vector<EdgePoint> foreign;
  for (const EdgePoint& e : edges) {
    const Eigen::Vector2d p{e.position.x, e.position.y};
    const Eigen::Vector2d radial = p - circle.centre;
    const double d = radial.norm();
    if (d == 0.0) continue;
    const Eigen::Vector2d normal{e.normal.x, e.normal.y};
    const double off = ellipse ? rim_ellipse::residual(*ellipse, p) : d - circle.radius;
    const double cosA = rimSign * (ellipse ? normal.dot(rim_ellipse::outwardNormal(*ellipse, p))
                                           : normal.dot(radial) / d);
    if (e.magnitude >= highThreshold && (std::abs(off) > 1.0 || cosA < cosTol))
      foreign.push_back(e);
  }
  return foreign;
}

// What the rim is when the circle fit kept `in` of its candidates `pts`: an ellipse (`fit`), a
// circle (neither field set), or an ellipse too little of which is measurable (`refusal`).
struct RimShape {
  std::optional<rim_ellipse::Fit> fit;
  std::string refusal;
  // `fit` is an ellipse that passed every test but the coverage: the grey values decide
  // (fitRimGreyValues), `refusal` (or the circle, when empty) stands if they cannot.
  bool partial = false;
  [[nodiscard]] bool adopted() const { return fit && !partial; }
};

// The ellipse is the rim when it takes in at least the circle's points, explains them
// significantly better, covers nearly the whole rim, lies in the annulus and is no flatter than
// a circle's view at 60 degrees. Looked for only when the circle gives cause: a significant
// second harmonic in its residuals (a mild tilt: the circle keeps every point, its grey-value fit
// does not fit them) or a tenth of the rim's candidates left out (the circle keeps the arcs it
// matches). A round rim pays for neither test's ellipse. An ellipse that explains a quarter more
// of the rim than the circle, with axes too far apart for the circle's band to hold, but fails
// the rest (a sector of it hidden, too flat, outside the annulus) refuses the rim: the circle's
// centre would be pixels off (bench_circle's clutter and occluder on an ellipse of axes 0.9 apart
// at r = 30: 2-5 px, status ok) and so, on half a rim with clutter, can an ellipse's.
RimShape rimShape(const std::vector<Eigen::Vector2d>& pts,
                  const std::vector<Eigen::Vector2d>& normals,
                  const std::vector<Eigen::Vector2d>& in, const Circle& circle,
                  const CircleMeasureParams& params, double cosHyp) {
  const bool leftOut = 10 * (pts.size() - in.size()) > in.size();
  if (!leftOut && rim_ellipse::secondHarmonicChiSquare(in, circle) <= kEllipseF) return {};
  const Eigen::Vector2d c0{params.centre.x, params.centre.y};
  auto judge = [&](std::optional<rim_ellipse::Fit> fit) -> RimShape {
    if (!fit || fit->inliers.size() < in.size() || !(fit->fStatistic > kEllipseF)) return {};
    const rim_ellipse::Ellipse& e = fit->ellipse;
    const double coverage = coverageDeg(fit->inliers, Circle{e.centre, e.meanRadius()});
    const bool shapeFits =
        e.major <= params.radius + params.width && e.minor >= params.radius - params.width &&
        (e.centre - c0).norm() <= params.width && e.minor >= kMinAxesRatio * e.major;
    if (shapeFits && coverage >= kMinEllipseCoverageDeg) return {std::move(fit), "", false};
    const bool partial = shapeFits && coverage >= params.minCoverageDeg;
    // Refused only when the circle cannot have held this ellipse (its band of +-ransacThreshold
    // holds a rim whose axes differ by less than twice that) and the points it left out are as
    // many as a measurement needs: otherwise they are clutter the ellipse bent to (a round rim of
    // r = 10 px with clutter and an occluder in bench_circle: 9 points more, axes 1.3 px apart).
    const std::size_t more = fit->inliers.size() - in.size();
    const bool refuse = 4 * more >= in.size() && static_cast<int>(more) >= params.minInliers &&
                        e.major - e.minor > 2.0 * params.ransacThreshold;
    if (!refuse) return partial ? RimShape{std::move(fit), "", true} : RimShape{};
    // The message before the fit moves out of reach.
    std::string refusal = cv::format(
        "the rim is an ellipse (axes %.2f x %.2f px, %zu of its edge points, a circle fits %zu) "
        "that this view does not let measure: %s",
        2 * e.major, 2 * e.minor, fit->inliers.size(), in.size(),
        coverage < kMinEllipseCoverageDeg
            ? cv::format("its points cover %.0f degrees, less than %.0f", coverage,
                         kMinEllipseCoverageDeg)
                  .c_str()
            : "it is flatter than a view at 60 degrees or leaves the annulus");
    return {partial ? std::move(fit) : std::nullopt, std::move(refusal), partial};
  };
  RimShape shape =
      judge(rim_ellipse::fitRimEllipse(pts, normals, in, params.ransacThreshold, cosHyp));
  // Grown from a circle that locked onto one side of the rim, the ellipse can stay there; from
  // all the rim's candidates it starts from the whole rim. A partial ellipse gives way to a
  // whole one or to one that takes in more points.
  if (leftOut && !shape.adopted() && (shape.partial || shape.refusal.empty())) {
    RimShape second = judge(rim_ellipse::fitRimEllipse(
        pts, normals, rim_ellipse::ellipseConsensus(pts, normals, params.ransacThreshold, cosHyp),
        params.ransacThreshold, cosHyp));
    if (second.adopted() || !shape.fit ||
        (second.fit && second.fit->inliers.size() > shape.fit->inliers.size()))
      shape = std::move(second);
  }
  return shape;
}

// The grey-value stage of a measurement: its fit, the rim's shape it was fitted with (an ellipse,
// or none: a circle), the rim points that chose its sectors, the rim's edge points within the
// RANSAC threshold of the fitted shape, and a refusal when the grey values say the rim is not
// round and no ellipse fits them.
struct GreyRim {
  std::optional<CircleProfileFit> fit;
  std::optional<rim_ellipse::Ellipse> shape;
  std::vector<cv::Point2d> rim;
  std::vector<Eigen::Vector2d> on;
  std::string refusal;
};

std::vector<cv::Point2d> imagePoints(const std::vector<Eigen::Vector2d>& pts) {
  std::vector<cv::Point2d> out;
  out.reserve(pts.size());
  for (const auto& p : pts) out.emplace_back(p.x(), p.y());
  return out;
}

// The shape step's size in its own standard deviations, squared (a Wald statistic).
double stepChiSquare(const CircleProfileFit& fit) {
  return (fit.shapeStep.t() * fit.shapeInformation * fit.shapeStep)(0);
}

// A shape is settled when its next step moves the rim by less than 1e-3 px or by less than the
// step's standard deviation. A big rim's fit keeps a share of its band's pixels, a different
// share for each shape: there the steps stay at a standard deviation or so, each one a
// different sample's noise (r = 100 px, axes 0.97 apart: 0.5 to 3 in chi-square, 5e-3 px).
bool settled(const CircleProfileFit& fit) {
  return fit.radius * cv::norm(fit.shapeStep) < 1e-3 || stepChiSquare(fit) < 1.0;
}

// The grey-value fit of a rim from `shape` (an ellipse, or none: a circle) and the rim points
// `rim` that choose its sectors. The grey fit only uses the sectors the rim points cover, and
// clutter that pulls the edge points' circle can push a clean arc of the rim out of the inliers
// (or out as a stray arc): at r = 10 px a lost third of the rim cost 0.1 px. The grey fit is
// several times more precise, so rim points within the RANSAC threshold of it are re-collected,
// and the grey fit is repeated when they are more than before. An ellipse's shape is fitted to
// the grey values too: the fit's step of the shape is taken and the fit repeated until the step
// is settled (the edge points' ellipse on a partly hidden rim of r = 10 px was up to a pixel off
// in its centre); a shape whose last step is still far beyond its noise
// (kUnsettledShapeChiSquare) is refused. `judgeShape`: a circle's fit also tests for a second
// harmonic.
GreyRim fitGreyRim(const cv::Mat& image, const CircleMeasurement& m,
                   const std::vector<Eigen::Vector2d>& rimCandidates, Circle around,
                   std::optional<rim_ellipse::Ellipse> shape, std::vector<cv::Point2d> rim,
                   bool judgeShape, const CircleMeasureParams& params, double cosTol) {
  GreyRim best;
  bool reshaped = false;
  for (int round = 0, rounds = shape ? 12 : 2; round < rounds; ++round) {
    const auto fit = fitCircleProfile(
        image, {around.centre.x(), around.centre.y()}, around.radius, rim,
        foreignEdges(m.annulusEdges, m.highThreshold, around, shape, m.rimSign, cosTol),
        m.noiseSigma, reshaped ? 2.0 : 1.0, shape ? shape->toCircle() : cv::Matx22d::eye(),
        judgeShape || shape.has_value());
    if (!fit) break;
    around = {Eigen::Vector2d{fit->centre.x, fit->centre.y}, fit->radius};
    if (shape) {
      const double scale = fit->radius / shape->meanRadius();
      shape->centre = around.centre;
      shape->major *= scale;
      shape->minor *= scale;
    }
    std::vector<Eigen::Vector2d> on;
    on.reserve(rimCandidates.size());
    for (const auto& p : rimCandidates)
      if (std::abs(shape ? rim_ellipse::residual(*shape, p) : residual(around, p)) <=
          params.ransacThreshold)
        on.push_back(p);
    best = {fit, shape, rim, on, ""};
    const bool more = on.size() > rim.size();
    if (more) rim = imagePoints(on);
    const bool reshape = shape && !settled(*fit);
    if (reshape) shape = rim_ellipse::reshaped(*shape, fit->shapeStep[0], fit->shapeStep[1]);
    reshaped = reshaped || reshape;
    if (!more && !reshape) return best;
  }
  if (best.shape && stepChiSquare(*best.fit) > kUnsettledShapeChiSquare)
    best.refusal = cv::format(
        "the rim's grey values fit no ellipse: its shape did not settle (the last step moved "
        "the rim by %.3f px, %.1f of its standard deviations)",
        best.fit->radius * cv::norm(best.fit->shapeStep), std::sqrt(stepChiSquare(*best.fit)));
  return best;
}

// The grey-value stage of a measurement (fitGreyRim) with its judgement of the rim's shape
// (`judgeShape`). The edge points' ellipse, if they found one (`ellipse`), is fitted as such.
// Else the circle is fitted, and a second harmonic in its fit (CircleProfileFit::secondHarmonic
// beyond kGreyEllipseChiSquare; on bench_circle's round rims, both blur models, every case, its
// chi-square stayed below 16 in 2,460 measurements) makes the rim an ellipse, refined in the
// grey values from the circle's fit's own step and from the ellipse the edge points fitted
// significantly better than the circle but could not accept (a sector of the rim hidden:
// `candidate`); of the two, the one more of the rim's edge points lie on is kept. Without a
// candidate the ellipse is kept only on a nearly whole rim (kMinEllipseCoverageDeg: on part of a
// rim an ellipse's stretch and centre trade off). When no ellipse is kept the rim is refused.
// When the circle's fit fails, the candidate is fitted instead and kept if the grey values fit
// it clearly not round (kPartialEllipseChiSquare).
GreyRim fitRimGreyValues(const cv::Mat& image, const CircleMeasurement& m,
                         const std::vector<Eigen::Vector2d>& rimCandidates, const Circle& circle,
                         const std::optional<rim_ellipse::Ellipse>& ellipse,
                         const std::optional<rim_ellipse::Fit>& candidate, bool judgeShape,
                         const CircleMeasureParams& params, double cosTol) {
  auto fit = [&](const Circle& around, const std::optional<rim_ellipse::Ellipse>& shape,
                 std::vector<cv::Point2d> rim) {
    return fitGreyRim(image, m, rimCandidates, around, shape, std::move(rim), judgeShape, params,
                      cosTol);
  };
  if (ellipse || !judgeShape) return fit(circle, ellipse, m.inlierPoints);
  const std::vector<cv::Point2d> candidatePoints =
      candidate ? imagePoints(candidate->inliers) : std::vector<cv::Point2d>{};
  auto fromCandidate = [&] {
    const rim_ellipse::Ellipse& e = candidate->ellipse;
    return fit({e.centre, e.meanRadius()}, e, candidatePoints);
  };
  // The circle is judged on the candidate's sectors too: on its own it chose the sectors it
  // fits (a circle locked onto arcs of an elliptic rim sees no harmonic there).
  std::vector<cv::Point2d> sectors = m.inlierPoints;
  sectors.insert(sectors.end(), candidatePoints.begin(), candidatePoints.end());
  GreyRim round = fit(circle, std::nullopt, std::move(sectors));
  if (!round.fit) {
    if (!candidate) return round;
    GreyRim oval = fromCandidate();
    if (!oval.fit || !oval.refusal.empty()) return round;
    const cv::Vec2d v = rim_ellipse::stretchOf(*oval.shape);
    return (v.t() * oval.fit->shapeInformation * v)(0) > kPartialEllipseChiSquare ? oval : round;
  }
  if (!(round.fit->secondHarmonic > kGreyEllipseChiSquare)) {
    // Round: measured on the circle's own sectors, those the candidate adds left out (on round
    // rims they are where clutter lent the candidate its points).
    if (!candidate) return round;
    GreyRim own = fit(circle, std::nullopt, m.inlierPoints);
    return own.fit ? own : round;
  }
  // The ellipse from the circle's fit's step, and from the candidate when there is one: each
  // start has its own basins (r = 10 px, 30% hidden: the candidate's shape a pixel off at axes
  // 0.97 apart, the step's at 0.9), so both are refined and the one that more of the rim's edge
  // points lie on is kept.
  const cv::Vec2d step = round.fit->shapeStep;
  const Circle fitted{{round.fit->centre.x, round.fit->centre.y}, round.fit->radius};
  GreyRim oval =
      fit(fitted,
          rim_ellipse::reshaped({fitted.centre, fitted.radius, fitted.radius, {1.0, 0.0}}, step[0],
                                step[1]),
          round.rim);
  if (candidate) {
    GreyRim other = fromCandidate();
    // A settled shape before one that is not, then the one more edge points lie on.
    const bool otherFirst =
        other.fit && (!oval.fit || (other.refusal.empty() != oval.refusal.empty()
                                        ? other.refusal.empty()
                                        : other.on.size() > oval.on.size()));
    if (otherFirst) oval = std::move(other);
    if (oval.fit) return oval;
  } else if (oval.fit && coverageDeg(oval.on, {oval.shape->centre, oval.shape->meanRadius()}) >=
                             kMinEllipseCoverageDeg) {
    return oval;
  }
  round.refusal = cv::format(
      "the rim's grey values are not those of a circle (their second harmonic's chi-square "
      "%.0f, more than %.1f) and no ellipse fitted to them could be kept",
      round.fit->secondHarmonic, kGreyEllipseChiSquare);
  return round;
}

// The rim's points and what they say of its fit: inliers, RMS from the rim's shape (the
// ellipse's, else the circle's), roundness (radial, about the circle), coverage (from `angles`,
// the inliers' sorted angles about the circle, when they are at hand) and the centre.
void describeRim(CircleMeasurement& m, const std::vector<Eigen::Vector2d>& in, const Circle& circle,
                 const std::optional<rim_ellipse::Ellipse>& ellipse,
                 const std::vector<double>* angles) {
  m.inliers = static_cast<int>(in.size());
  m.inlierPoints.clear();
  m.inlierPoints.reserve(in.size());
  double sum2 = 0, lo = 0, hi = 0;
  for (const auto& p : in) {
    const double r = residual(circle, p);  // radial: the roundness
    const double off = ellipse ? rim_ellipse::residual(*ellipse, p) : r;
    sum2 += off * off;
    lo = std::min(lo, r);
    hi = std::max(hi, r);
    m.inlierPoints.emplace_back(p.x(), p.y());
  }
  m.rms = in.empty() ? 0.0 : std::sqrt(sum2 / static_cast<double>(in.size()));
  m.roundness = hi - lo;
  m.coverageDeg = angles ? coverageDeg(*angles, circle.radius) : coverageDeg(in, circle);
  m.centre = {circle.centre.x(), circle.centre.y()};
}

// Edge point relative to the expected centre, with its radial alignment.
struct Candidate {
  Eigen::Vector2d p;
  Eigen::Vector2d normal;  // unit gradient direction (dark -> light)
  double radialCos = 0;    // cosine between the gradient and the outward radial
};

}  // namespace

std::string clippedRimRefusal(const CircleMeasurement& m, int depth) {
  if (!(m.clippedShare > kClippedRimShare)) return {};
  return cv::format(
      "the rim is clipped: %.0f%% of the pixels within %.0f px of it are at the sensor's limit "
      "(%s or 0), and its grey values could not be fitted as a clipped step (its middle beyond "
      "the limit, or no fit); its edge points alone lie up to a pixel off: lower the exposure or "
      "the light",
      100.0 * m.clippedShare, kClippedBand, depth == CV_16U ? "65535" : "255");
}

std::string_view toString(CircleFailure failure) {
  switch (failure) {
    case CircleFailure::None:
      return "";
    case CircleFailure::BadInput:
      return "bad_input";
    case CircleFailure::AnnulusOutsideImage:
      return "annulus_outside_image";
    case CircleFailure::TooFewPoints:
      return "too_few_points";
    case CircleFailure::CoverageTooSmall:
      return "coverage_too_small";
    case CircleFailure::FitTooPoor:
      return "fit_too_poor";
  }
  return "";
}

CircleMeasurement measureCircle(const cv::Mat& image, const CircleMeasureParams& params) {
  CircleMeasurement m;
  if (std::string why = checkParams(image, params); !why.empty())
    return failed(m, CircleFailure::BadInput, why);

  const double rIn = std::max(0.0, params.radius - params.width);
  const double rOut = params.radius + params.width;
  const cv::Point2d c0 = params.centre;

  // Canny thresholds from the annulus alone, then Facet subpixel points (annulus_edges.hpp).
  AnnulusEdges edges = detectAnnulusEdges(image, c0, rIn, rOut, params.cannyLow, params.cannyHigh);
  if (edges.annulusPixels == 0)
    return failed(m, CircleFailure::AnnulusOutsideImage,
                  "the search annulus around (" + readable(c0.x) + ", " + readable(c0.y) +
                      ") with radius " + readable(params.radius) + " +- " + readable(params.width) +
                      " lies outside the " + std::to_string(image.cols) + "x" +
                      std::to_string(image.rows) + " image");

  const bool annulusClipped = edges.clipped;
  m.lowThreshold = edges.lowThreshold;
  m.highThreshold = edges.highThreshold;
  m.edgePoints = static_cast<int>(edges.points.size());

  // Gradient-direction test against the expected centre.
  const double cosTol = std::cos(params.directionToleranceDeg * kPi / 180.0);
  std::vector<Candidate> candidates;
  candidates.reserve(edges.points.size());
  for (const EdgePoint& e : edges.points) {
    const Eigen::Vector2d p{e.position.x, e.position.y};
    const Eigen::Vector2d radial = p - Eigen::Vector2d{c0.x, c0.y};
    const double d = radial.norm();
    if (d < rIn || d > rOut || d == 0.0) continue;
    const double cosA = (e.normal.x * radial.x() + e.normal.y * radial.y()) / d;
    const bool darkToLight = cosA >= cosTol, lightToDark = cosA <= -cosTol;
    const bool keep = params.polarity == CirclePolarity::DarkToLight   ? darkToLight
                      : params.polarity == CirclePolarity::LightToDark ? lightToDark
                                                                       : darkToLight || lightToDark;
    if (keep) candidates.push_back({p, {e.normal.x, e.normal.y}, cosA});
  }
  m.candidates = static_cast<int>(candidates.size());
  if (m.candidates < params.minInliers)
    return failed(m, CircleFailure::TooFewPoints,
                  std::to_string(m.candidates) +
                      " edge points with a radial gradient in the annulus, fewer than the " +
                      std::to_string(params.minInliers) + " required");

  // RANSAC, once per polarity when either is allowed: a circle's rim has one polarity.
  const double cosHyp = std::cos(kHypothesisToleranceDeg * kPi / 180.0);
  RansacParams rp;
  rp.inlierThreshold = params.ransacThreshold;
  rp.maxIterations = 500;
  std::optional<Circle> best;
  std::vector<Eigen::Vector2d> bestPts, bestNormals;
  std::size_t bestCount = 0;
  int rimSign = +1;  // +1: gradient points outwards (dark inside), -1: inwards
  for (int sign : {+1, -1}) {
    std::vector<Eigen::Vector2d> pts, normals;
    pts.reserve(candidates.size());
    normals.reserve(candidates.size());
    for (const Candidate& c : candidates)
      if (c.radialCos * sign > 0) {
        pts.push_back(c.p);
        normals.push_back(sign * c.normal);  // outwards for either polarity
      }
    if (static_cast<int>(pts.size()) < params.minInliers || pts.size() <= bestCount) continue;
    const Eigen::Vector2d e0{c0.x, c0.y};
    auto fit = [&](const std::vector<std::size_t>& s) -> std::optional<Circle> {
      auto c = circleThrough(pts[s[0]], pts[s[1]], pts[s[2]]);
      // A circle that cannot lie in the annulus is clutter, not the rim.
      if (!c || std::abs(c->radius - params.radius) > params.width ||
          (c->centre - e0).norm() > params.width)
        return std::nullopt;
      return c;
    };
    // An inlier lies near the circle AND its gradient points along the circle's radial: a
    // straight edge (an occluder's border) just outside an occluded sector meets a wrong circle
    // in a few points at the right distance, but its normals fan away from that circle's radials.
    auto res = [&](const Circle& c, std::size_t i) {
      const Eigen::Vector2d radial = pts[i] - c.centre;
      const double n = radial.norm();
      if (n == 0.0 || normals[i].dot(radial) < cosHyp * n)
        return std::numeric_limits<double>::infinity();
      return std::abs(n - c.radius);
    };
    auto found = ransac<Circle>(pts.size(), 3, fit, res, rp);
    if (found && found->inliers.size() > bestCount) {
      bestCount = found->inliers.size();
      rimSign = sign;
      best = found->model;
      bestPts = std::move(pts);
      bestNormals = std::move(normals);
    }
  }
  if (!best || static_cast<int>(bestCount) < params.minInliers)
    return failed(m, CircleFailure::TooFewPoints,
                  "no circle with at least " + std::to_string(params.minInliers) +
                      " consistent edge points in the annulus");

  // Geometric fit on the RANSAC inliers, then re-collect the inliers around the refined circle
  // and refit with the robust weight.
  std::vector<Eigen::Vector2d> in;
  const std::vector<Eigen::Vector2d> rimCandidates = bestPts;  // before stray arcs leave
  std::optional<Circle> fitted = fitRim(bestPts, *best, params, in);
  // Drop runs of inliers the rest of the rim disagrees with, worst first, and refit. When the
  // last look finds none, its sorted angles are those of the final inliers around the final
  // circle: the coverage below takes them instead of computing and sorting them again.
  std::vector<double> angles;
  bool anglesFinal = false;
  for (int round = 0; round < 3 && fitted; ++round) {
    const std::vector<Eigen::Vector2d> stray = strayArc(in, *fitted, params, angles);
    if (stray.empty()) {
      anglesFinal = true;
      break;
    }
    std::erase_if(bestPts, [&](const Eigen::Vector2d& p) {
      return std::find(stray.begin(), stray.end(), p) != stray.end();
    });
    fitted = fitRim(bestPts, *fitted, params, in);
  }
  if (!fitted)
    return failed(m, CircleFailure::FitTooPoor, "the geometric circle fit did not converge");
  // An elliptic rim (a tilted view, an oval part) is measured as its ellipse: the circle keeps
  // the arcs it matches, on one side, and its centre moves along the minor axis (rim_ellipse.hpp).
  // Its centre and the circle of its area are then the result.
  std::optional<rim_ellipse::Ellipse> ellipse;
  std::optional<rim_ellipse::Fit> candidate;  // for the grey values to judge
  std::string ellipseRefusal;
  if (params.measureEllipticRims) {
    RimShape shape = rimShape(rimCandidates, bestNormals, in, *fitted, params, cosHyp);
    if (shape.adopted()) {
      ellipse = shape.fit->ellipse;
      in = std::move(shape.fit->inliers);
    } else if (shape.partial) {
      candidate = std::move(shape.fit);
    }
    ellipseRefusal = std::move(shape.refusal);
  }
  const Circle circle = ellipse ? Circle{ellipse->centre, ellipse->meanRadius()} : *fitted;
  m.annulusEdges = std::move(edges.points);
  m.rimSign = rimSign;
  m.noiseSigma = edges.noiseSigma;
  describeRim(m, in, circle, ellipse, anglesFinal && !ellipse ? &angles : nullptr);
  const double bias = params.correctRadiusBias ? params.radiusBiasK / circle.radius : 0.0;
  m.radius = circle.radius + bias;
  m.diameter = 2.0 * m.radius;

  if (m.inliers < params.minInliers)
    return failed(m, CircleFailure::TooFewPoints,
                  std::to_string(m.inliers) + " inliers, fewer than the " +
                      std::to_string(params.minInliers) + " required");
  // An ellipse the edge points alone cannot judge waits for the grey values' judgement.
  const bool greyJudge = params.refineWithGreyValues && params.measureEllipticRims;
  const bool judgedByGrey = candidate && greyJudge;
  if (!ellipseRefusal.empty() && !judgedByGrey)
    return failed(m, CircleFailure::FitTooPoor, ellipseRefusal);
  auto rimFails = [&]() -> std::optional<CircleMeasurement> {
    if (m.coverageDeg < params.minCoverageDeg)
      return failed(m, CircleFailure::CoverageTooSmall,
                    "the inliers cover " + readable(m.coverageDeg) + " degrees, less than " +
                        readable(params.minCoverageDeg));
    if (m.rms > params.maxRms)
      return failed(m, CircleFailure::FitTooPoor,
                    "the fit's rms " + readable(m.rms) + " px exceeds " + readable(params.maxRms));
    return std::nullopt;
  };
  if (!judgedByGrey)
    if (auto fails = rimFails()) return std::move(*fails);

  if (params.refineWithGreyValues) {
    const GreyRim grey = fitRimGreyValues(image, m, rimCandidates, circle, ellipse, candidate,
                                          params.measureEllipticRims, params, cosTol);
    if (!grey.refusal.empty()) return failed(m, CircleFailure::FitTooPoor, grey.refusal);
    if (grey.fit) {
      // The grey values' ellipse answers the edge points' refusal; their circle does not when
      // the edge points' ellipse holds a quarter more of the rim (r = 10 px, 30% hidden, axes
      // 0.8 apart: a circle 3.5 px off, its grey fit on arcs it chose finding no harmonic).
      if (grey.shape) ellipseRefusal.clear();
      if (grey.shape && !ellipse) {
        // The rim became an ellipse in the grey values: its points are the ellipse's.
        describeRim(m, grey.on, {grey.shape->centre, grey.shape->meanRadius()}, grey.shape,
                    nullptr);
      }
      ellipse = grey.shape;
      if (judgedByGrey)
        if (auto fails = rimFails()) return std::move(*fails);
      m.centre = grey.fit->centre;
      m.radius = grey.fit->radius;
      m.diameter = 2.0 * m.radius;
      m.blur = grey.fit->blur;
      m.greyRefined = true;
    }
  }
  if (!ellipseRefusal.empty()) return failed(m, CircleFailure::FitTooPoor, ellipseRefusal);
  if (judgedByGrey && !m.greyRefined)
    return failed(
        m, CircleFailure::FitTooPoor,
        cv::format("the rim's edge points fit an ellipse (axes %.2f x %.2f px) better than a "
                   "circle, on too little of the rim to accept it, and no grey-value fit told "
                   "which it is",
                   2 * candidate->ellipse.major, 2 * candidate->ellipse.minor));
  // A rim clipped by the sensor: its edge points alone are off (CircleMeasurement::clippedShare).
  // Looked for only when the annulus's noise estimate met a clipped pixel (most images: none).
  const double halfSpread = ellipse ? (ellipse->major - ellipse->minor) / 2.0 : 0.0;
  if (annulusClipped)
    m.clippedShare = rim_band::clippedShare(image, m.centre, m.radius - kClippedBand - halfSpread,
                                            m.radius + kClippedBand + halfSpread);
  if (params.refineWithGreyValues && !m.greyRefined)
    if (std::string why = clippedRimRefusal(m, image.depth()); !why.empty())
      return failed(m, CircleFailure::FitTooPoor, std::move(why));
  // The edge points' tests of an ellipse (rimShape), for one the grey values made.
  if (ellipse && (ellipse->minor < kMinAxesRatio * ellipse->major ||
                  ellipse->major > params.radius + params.width ||
                  ellipse->minor < params.radius - params.width))
    return failed(m, CircleFailure::FitTooPoor,
                  cv::format("the rim is an ellipse (axes %.2f x %.2f px) %s", 2 * ellipse->major,
                             2 * ellipse->minor,
                             ellipse->minor < kMinAxesRatio * ellipse->major
                                 ? "flatter than a view at 60 degrees"
                                 : "that leaves the search annulus"));
  // The axes, scaled as the radius was from the ellipse's mean (the edge points' bias, the grey
  // fit); both the diameter on a round rim.
  m.majorDiameter = m.minorDiameter = m.diameter;
  if (ellipse) {
    m.elliptic = true;
    const double scale = m.radius / ellipse->meanRadius();
    m.majorDiameter = 2.0 * ellipse->major * scale;
    m.minorDiameter = 2.0 * ellipse->minor * scale;
    // Counter-clockwise on screen (y down), in [0, 180).
    const double deg = -std::atan2(ellipse->axis.y(), ellipse->axis.x()) * 180.0 / kPi;
    m.majorAxisDeg = deg < 0.0 ? deg + 180.0 : (deg >= 180.0 ? deg - 180.0 : deg);
  }
  if (std::abs(m.radius - params.radius) > params.width ||
      std::hypot(m.centre.x - c0.x, m.centre.y - c0.y) > params.width)
    return failed(m, CircleFailure::FitTooPoor, "the fitted circle leaves the search annulus");
  return m;
}

}  // namespace facet
