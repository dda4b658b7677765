#include "algorithms/calibration/plane_circle_profile.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <limits>
#include <numbers>
#include <span>
#include <utility>

#include <Eigen/Dense>
#include <opencv2/imgproc.hpp>

#include "algorithms/calibration/plane_patch.hpp"
#include "algorithms/circle/censored_pixels.hpp"
#include "algorithms/circle/rim_band.hpp"
#include "algorithms/circle/step_profile.hpp"
#include "algorithms/circle/weighted_normal_equations.hpp"
#include "algorithms/edges/row_runs.hpp"
#include "algorithms/geometry/levenberg_marquardt.hpp"
#include "algorithms/image/sensor_limit.hpp"

namespace facet {
namespace {

constexpr double kPi = std::numbers::pi;
// As fitCircleProfile's: a rim under kSmallRim px keeps a wider band and every covered bin.
constexpr double kSmallRim = 25.0;
// Share of the band's pixels that contaminated sectors must hold before the fit is repeated.
constexpr double kMinRefitShare = 0.02;

using Vector8 = Eigen::Matrix<double, 8, 1>;
using Matrix8 = Eigen::Matrix<double, 8, 8>;
using Free = std::array<bool, 8>;

// Parameters: centre offset from the start (x, y) and radius, in units of `unit` mm (the plane's
// scale at the start, so that all lengths are about image pixels), blur s, outside level a0,
// ramp (x, y), contrast b.
enum Parameter { kCx, kCy, kRadius, kBlur, kLevel, kRampX, kRampY, kContrast };

// The angular bin, of `bins` equal angles, of an offset from the centre in the plane.
int binOf(cv::Point2d offset, int bins) {
  double a = std::atan2(offset.y, offset.x);
  if (a < 0) a += 2 * kPi;
  return std::min(bins - 1, static_cast<int>(a / (2 * kPi) * bins));
}

using Columns = Eigen::Matrix<double, Eigen::Dynamic, 8>;

// The band's pixels as the fit uses them, one column per quantity, so that the model's pass over
// them vectorises (as fitCircleProfile's does).
struct RimBand {
  Eigen::VectorXd mmX, mmY;          // place in the plane, relative to the start centre
  Eigen::VectorXd xAlongX, yAlongX;  // the plane's derivative along the image's x, mm per pixel
  Eigen::VectorXd xAlongY, yAlongY;  // ... and along its y
  Eigen::VectorXd x, y;              // the pixel, relative to the start centre's image
  Eigen::VectorXd grey;
  std::vector<int> bin;

  [[nodiscard]] Eigen::Index size() const { return grey.size(); }
  [[nodiscard]] std::array<Eigen::VectorXd*, 9> columns() {
    return {&mmX, &mmY, &xAlongX, &yAlongX, &xAlongY, &yAlongY, &x, &y, &grey};
  }
  void resize(Eigen::Index n) {
    for (Eigen::VectorXd* c : columns()) c->resize(n);
    bin.resize(static_cast<std::size_t>(n));
  }
  void set(Eigen::Index i, const PlanePixel& p, cv::Point2d mm, cv::Point2d px, double g, int b) {
    mmX(i) = mm.x, mmY(i) = mm.y;
    xAlongX(i) = p.alongX.x, yAlongX(i) = p.alongX.y;
    xAlongY(i) = p.alongY.x, yAlongY(i) = p.alongY.y;
    x(i) = px.x, y(i) = px.y, grey(i) = g;
    bin[static_cast<std::size_t>(i)] = b;
  }
  [[nodiscard]] RimGeometry geometryAt(Eigen::Index i, cv::Point2d centre, double radius) const;
  // Keeps the pixels whose bin `drop` does not mark, in order.
  void keep(const std::vector<std::uint8_t>& drop) {
    Eigen::Index k = 0;
    for (Eigen::Index i = 0; i < size(); ++i) {
      if (drop[static_cast<std::size_t>(bin[static_cast<std::size_t>(i)])]) continue;
      for (Eigen::VectorXd* c : columns()) (*c)(k) = (*c)(i);
      bin[static_cast<std::size_t>(k++)] = bin[static_cast<std::size_t>(i)];
    }
    for (Eigen::VectorXd* c : columns()) c->conservativeResize(k);
    bin.resize(static_cast<std::size_t>(k));
  }
};

// rimGeometry, inlined into the loops over the band's pixels.
inline RimGeometry rimGeometryAt(cv::Point2d offset, cv::Point2d alongX, cv::Point2d alongY,
                                 double radiusMm) {
  const double rho = std::max(std::sqrt(offset.x * offset.x + offset.y * offset.y), 1e-12);
  const cv::Point2d u = offset / rho;
  // The gradient, with respect to the pixel, of the distance from the centre in the plane.
  const cv::Point2d g(alongX.dot(u), alongY.dot(u));
  const double k = std::max(std::sqrt(g.x * g.x + g.y * g.y), 1e-12);
  return {(rho - radiusMm) / k, k, u, g / k};
}

RimGeometry RimBand::geometryAt(Eigen::Index i, cv::Point2d centre, double radius) const {
  return rimGeometryAt(cv::Point2d(mmX(i), mmY(i)) - centre, {xAlongX(i), yAlongX(i)},
                       {xAlongY(i), yAlongY(i)}, radius);
}

// The model's pass over the band with the Gaussian profile: residuals (grey - model) and the
// Jacobian's columns that change (centre, radius, blur, contrast); rimGeometryAt written out per
// column. A function of its own so that the arrays can be declared distinct (__restrict) and the
// loop vectorises: as a loop over the pixels' structures it was a fifth of a calibrated circle's
// time.
FACET_PIXEL_PASS void evaluateGaussianBand(
    const Vector8& v, double unit, std::ptrdiff_t n, const double* __restrict mmX,
    const double* __restrict mmY, const double* __restrict xAlongX,
    const double* __restrict yAlongX, const double* __restrict xAlongY,
    const double* __restrict yAlongY, const double* __restrict x, const double* __restrict y,
    const double* __restrict grey, double* __restrict out, double* __restrict jcx,
    double* __restrict jcy, double* __restrict jr, double* __restrict js, double* __restrict jb) {
  const double cx = unit * v(kCx), cy = unit * v(kCy), radius = unit * v(kRadius), s = v(kBlur),
               level = v(kLevel), rampX = v(kRampX), rampY = v(kRampY), b = v(kContrast);
  const double inv = 1.0 / s, bNorm = b / (std::sqrt(2.0 * kPi) * s);
  for (std::ptrdiff_t i = 0; i < n; ++i) {
    const double ox = mmX[i] - cx, oy = mmY[i] - cy;
    const double rho = std::max(std::sqrt(ox * ox + oy * oy), 1e-12);
    const double ux = ox / rho, uy = oy / rho;
    const double gx = xAlongX[i] * ux + yAlongX[i] * uy, gy = xAlongY[i] * ux + yAlongY[i] * uy;
    const double k = std::max(std::sqrt(gx * gx + gy * gy), 1e-12);
    const double z = (rho - radius) / k * inv, gauss = step_profile::gaussian(z);
    const double phi = step_profile::upperTail(z, gauss);  // Phi(-d / s)
    const double bg = bNorm * gauss;                       // -dI/dd
    out[i] = grey[i] - (level + rampX * x[i] + rampY * y[i] + b * phi);
    // dd/dC = -u unit / k (the change of the rim's scale with C is second order near it).
    const double perUnit = bg * unit / k;
    jcx[i] = perUnit * ux;
    jcy[i] = perUnit * uy;
    jr[i] = perUnit;
    js[i] = bg * z;
    jb[i] = phi;
  }
}

// The same pass with each pixel's area in the model (the sharp images'; step_profile::pixelStep).
void evaluatePixelBand(const Vector8& v, double unit, const RimBand& band, double* out,
                       Columns& j) {
  const cv::Point2d c = unit * cv::Point2d(v(kCx), v(kCy));
  const double radius = unit * v(kRadius), s = v(kBlur), b = v(kContrast);
  for (Eigen::Index i = 0; i < band.size(); ++i) {
    const RimGeometry g = band.geometryAt(i, c, radius);
    const step_profile::PixelStep p =
        step_profile::pixelStep(g.distance, s, g.imageNormal.x, g.imageNormal.y);
    out[i] =
        band.grey(i) - (v(kLevel) + v(kRampX) * band.x(i) + v(kRampY) * band.y(i) + b * p.value);
    const double perUnit = -b * p.dd * unit / g.scale;  // dI/dd dd/dC, dd/dC = -u unit / k
    j(i, kCx) = perUnit * g.planeNormal.x;
    j(i, kCy) = perUnit * g.planeNormal.y;
    j(i, kRadius) = perUnit;
    j(i, kBlur) = b * p.ds;
    j(i, kContrast) = p.value;
  }
}

}  // namespace

RimGeometry rimGeometry(cv::Point2d offset, cv::Point2d alongX, cv::Point2d alongY,
                        double radiusMm) {
  return rimGeometryAt(offset, alongX, alongY, radiusMm);
}

std::optional<PlaneCircleProfileFit> fitPlaneCircleProfile(
    const cv::Mat& image, const WorldMapping& plane, cv::Point2d centreMm, double radiusMm,
    const std::vector<cv::Point2d>& rimPoints, const std::vector<EdgePoint>& foreignPoints,
    double noiseSigma, double maxShiftPx) {
  if (image.empty() || image.channels() != 1 ||
      (image.depth() != CV_8U && image.depth() != CV_16U) || !(radiusMm > 0) ||
      rimPoints.size() < 3)
    return std::nullopt;
  const cv::Point2d centrePx = plane.toImage(centreMm);
  const double unit = plane.mmPerPixelAt(centrePx);
  if (!std::isfinite(centrePx.x) || !std::isfinite(centrePx.y) || !(unit > 0)) return std::nullopt;
  const double radiusPx = radiusMm / unit;
  if (radiusPx <= 1.0) return std::nullopt;

  // Angular bins (in the plane) of about 2 px of arc; a bin takes part when an inlier edge point
  // lies in it (fitCircleProfile's rule).
  const bool smallRim = radiusPx < kSmallRim;
  const int bins = std::max(16, static_cast<int>(2.0 * kPi * radiusPx / 2.0));
  std::vector<std::uint8_t> covered(static_cast<std::size_t>(bins), 0);
  for (const cv::Point2d& p : rimPoints) {
    const cv::Point2d q = plane.toPlane(p);
    if (!std::isfinite(q.x) || !std::isfinite(q.y)) return std::nullopt;
    covered[static_cast<std::size_t>(binOf(q - centreMm, bins))] = 1;
  }
  covered = rim_band::closedCoverage(covered, smallRim ? 0 : 1);
  const double halfBand = smallRim ? 8.0 : 6.0;  // image pixels, as fitCircleProfile's

  // The band's image lies between two circles about the centre's image: through the nearest
  // and the farthest image of the plane points halfBand image pixels inside and outside the rim
  // (at 72 angles, each with the plane's scale across the rim there, plus a margin). Only their
  // annulus is visited, clipped 1 px inside the image (the gradient screen needs each pixel's
  // neighbours). The scale comes from the projection's derivatives, inverted: projecting is a
  // closed form, mapping an image point into the plane an iterative undistortion.
  double nearest = std::numeric_limits<double>::infinity(), farthest = 0.0;
  for (int i = 0; i < 72; ++i) {
    const cv::Point2d along(std::cos(2 * kPi * i / 72), std::sin(2 * kPi * i / 72));
    const cv::Point2d atMm = centreMm + radiusMm * along;
    const cv::Point2d rim = plane.toImage(atMm);
    const double h = 1e-3 * radiusMm;
    const cv::Point2d byX = (plane.toImage(atMm + cv::Point2d(h, 0)) - rim) / h;  // px per mm
    const cv::Point2d byY = (plane.toImage(atMm + cv::Point2d(0, h)) - rim) / h;
    const cv::Matx22d toMm = cv::Matx22d(byX.x, byY.x, byX.y, byY.y).inv();
    const double reach =
        1.2 * (halfBand + 1.0) *
        rimGeometry(along, {toMm(0, 0), toMm(1, 0)}, {toMm(0, 1), toMm(1, 1)}, 1.0).scale;
    const cv::Point2d in = plane.toImage(centreMm + std::max(0.0, radiusMm - reach) * along);
    const cv::Point2d out = plane.toImage(centreMm + (radiusMm + reach) * along);
    if (!std::isfinite(in.x + in.y + out.x + out.y)) return std::nullopt;
    nearest = std::min(nearest, cv::norm(in - centrePx));
    farthest = std::max(farthest, cv::norm(out - centrePx));
  }
  const cv::Rect box = cv::Rect(cv::Point(static_cast<int>(std::floor(centrePx.x - farthest)),
                                          static_cast<int>(std::floor(centrePx.y - farthest))),
                                cv::Point(static_cast<int>(std::ceil(centrePx.x + farthest)) + 1,
                                          static_cast<int>(std::ceil(centrePx.y + farthest)) + 1)) &
                       cv::Rect(1, 1, image.cols - 2, image.rows - 2);
  const auto patch = PlanePatch::over(plane, box);
  if (!patch) return std::nullopt;

  // The band: pixels within halfBand image pixels of the rim, in a covered bin, clear of foreign
  // edges. Each sample's offset is its rim normal in the image times its distance from the
  // centre of a circle of radius radiusPx: the gradient screen judges it by that.
  const rim_band::ForeignReach tainted(foreignPoints, noiseSigma, box);
  std::vector<rim_band::Sample> samples;
  std::vector<double> inside, outside;
  PlanePatch::Row row;
  int loaded = -1;  // the row of `row`
  for (const RowRun& run : annulusRowRuns(centrePx, nearest, farthest, box)) {
    if (run.y != loaded) patch->load(loaded = run.y, row);
    const std::uint8_t* taint = tainted.row(run.y);
    for (int x = run.x0; x < run.x1; ++x) {
      const PlanePixel p = row.at(x);
      const cv::Point2d offset = p.mm - centreMm;
      const RimGeometry g = rimGeometryAt(offset, p.alongX, p.alongY, radiusMm);
      if (std::abs(g.distance) > halfBand) continue;
      const int bin = binOf(offset, bins);
      if (!covered[static_cast<std::size_t>(bin)] || (taint != nullptr && taint[x] != 0)) continue;
      const double grey = rim_band::greyAt(image, x, run.y);
      if (g.distance < -2.0) inside.push_back(grey);
      if (g.distance > 2.0) outside.push_back(grey);
      const cv::Point2d o = g.imageNormal * (radiusPx + g.distance);
      samples.push_back({o.x, o.y, grey, bin, x, run.y});
    }
  }
  if (samples.size() < 30 || inside.empty() || outside.empty()) return std::nullopt;
  // A big clean rim needs far fewer pixels than it has: as fitCircleProfile, keep those within
  // kNarrowBand px of the rim in an evenly spread share of the bins, but four times as many as
  // rim_band::pixelsNeeded (half its centre precision target): a millimetre value on a calibrated
  // station is worth the time (at r = 29 px the image fit's share cost 1.5x in the diameter;
  // bench_plane_measures), and the time stays bounded. Every pixel of a faint rim stays.
  const double contrast = rim_band::medianOf(inside) - rim_band::medianOf(outside);
  constexpr double kPrecisionFactor = 4.0;
  auto wanted = [&](double halfWidth) {
    return kPrecisionFactor * rim_band::pixelsNeeded(contrast / noiseSigma, halfWidth);
  };
  if (noiseSigma > 0.0 && static_cast<double>(samples.size()) > wanted(halfBand)) {
    constexpr double kNarrowBand = 4.0;
    std::erase_if(samples, [&](const rim_band::Sample& e) {
      return std::abs(std::sqrt(e.x * e.x + e.y * e.y) - radiusPx) > kNarrowBand;
    });
    const double share = wanted(kNarrowBand) / static_cast<double>(samples.size());
    if (share < 1.0)
      std::erase_if(samples, [&](const rim_band::Sample& e) {
        return std::floor((e.bin + 1) * share) == std::floor(e.bin * share);
      });
  }
  if (noiseSigma > 0.0) {
    rim_band::dropForeignGradients(samples, image, radiusPx, noiseSigma, box);
    if (samples.size() < 30) return std::nullopt;
  }
  RimBand band;
  band.resize(static_cast<Eigen::Index>(samples.size()));
  for (std::size_t i = 0; i < samples.size(); ++i) {
    const rim_band::Sample& e = samples[i];
    const PlanePixel p = patch->at(cv::Point2d(e.column, e.row));
    band.set(static_cast<Eigen::Index>(i), p, p.mm - centreMm,
             {e.column - centrePx.x, e.row - centrePx.y}, e.grey, e.bin);
  }

  Vector8 q;
  const CensoredPixels::Step start = CensoredPixels::startingStep(
      rim_band::medianOf(outside), rim_band::medianOf(inside), sensorLimit(image.depth()));
  q << 0.0, 0.0, radiusPx, 1.2, start.level, 0.0, 0.0, start.contrast;
  const double tukeyC = noiseSigma > 0.0 ? 8.0 : 4.685;  // fitCircleProfile's reasons

  // Residuals (grey - model) and the model's Jacobian at parameters v. The Jacobian's columns of
  // the level and the ramp (1, x, y) never change: set once per band.
  Eigen::Index n = 0;
  Eigen::VectorXd r, rTry, weight;
  Columns jac, jacTry;
  CensoredPixels clipped;  // fitted as the sensor clipped them (censored_pixels.hpp)
  auto all = [&](Eigen::VectorXd& v) { return std::span<double>(v.data(), v.size()); };
  auto loadBand = [&] {
    n = band.size();
    clipped =
        CensoredPixels({band.grey.data(), static_cast<std::size_t>(n)}, sensorLimit(image.depth()));
    r.resize(n), rTry.resize(n);
    weight.setOnes(n);
    for (Columns* j : {&jac, &jacTry}) {
      j->resize(n, 8);
      j->col(kLevel).setOnes();
      j->col(kRampX) = band.x;
      j->col(kRampY) = band.y;
    }
  };
  loadBand();
  bool pixelModel = false;  // fitCircleProfile's model of sharp images (below)
  auto evaluate = [&](const Vector8& v, Eigen::VectorXd& res, Columns& j) {
    if (pixelModel) return evaluatePixelBand(v, unit, band, res.data(), j);
    evaluateGaussianBand(v, unit, n, band.mmX.data(), band.mmY.data(), band.xAlongX.data(),
                         band.yAlongX.data(), band.xAlongY.data(), band.yAlongY.data(),
                         band.x.data(), band.y.data(), band.grey.data(), res.data(),
                         j.col(kCx).data(), j.col(kCy).data(), j.col(kRadius).data(),
                         j.col(kBlur).data(), j.col(kContrast).data());
  };
  auto cost = [&](const Eigen::VectorXd& res) {
    return (weight.array() * res.array().square()).sum();
  };
  auto tukeyWeights = [&] {
    const double sigma = std::max(clipped.robustSigma(all(r)), 0.25);
    const double c = tukeyC * sigma;
    for (Eigen::Index i = 0; i < n; ++i) {
      const double u = std::abs(r(i)) / c;
      weight(i) = u >= 1.0 ? 0.0 : (1 - u * u) * (1 - u * u);
    }
    clipped.unweight(all(r), all(weight));
    return sigma;
  };
  Matrix8 jtj;
  Vector8 jtr;
  // J^T W J and J^T W r over the free parameters; a fixed one's row and column are the
  // identity's, so that the step leaves it alone.
  auto normalEquations = [&](const Free& free) {
    std::array<int, 8> index{};
    std::array<const double*, 8> columns{};
    int k = 0;
    for (int a = 0; a < 8; ++a)
      if (free[static_cast<std::size_t>(a)]) {
        index[static_cast<std::size_t>(k)] = a;
        columns[static_cast<std::size_t>(k++)] = jac.col(a).data();
      }
    std::array<double, 64> h{};
    std::array<double, 8> g{};
    weightedNormalEquations({columns.data(), static_cast<std::size_t>(k)}, weight.data(), r.data(),
                            n, h.data(), g.data());
    jtj.setIdentity();
    jtr.setZero();
    for (int u = 0; u < k; ++u) {
      jtr(index[static_cast<std::size_t>(u)]) = g[static_cast<std::size_t>(u)];
      for (int v = 0; v < k; ++v)
        jtj(index[static_cast<std::size_t>(u)], index[static_cast<std::size_t>(v)]) =
            h[static_cast<std::size_t>(u * k + v)];
    }
  };
  double sigma = 0.0;
  auto solve = [&](const Free& free) {
    LevenbergMarquardtCallbacks problem{
        [&](const Vector8& v) {
          evaluate(v, r, jac);
          clipped.censor(all(r));
          return cost(r);
        },
        [&](int, const Vector8&, Matrix8& h, Vector8& g, double& current) {
          // Robust weights at every step (iteratively re-weighted least squares): weights set at
          // the start's residuals (the edge points' circle, some hundredths of a pixel off)
          // down-weight the rim's steep pixels on one side and keep the solution near the start
          // (with them set in the first two steps only, radii on the demo recordings stayed
          // 0.012 px above the image fit's; a second and third solve halved that each time).
          sigma = tukeyWeights();
          current = cost(r);
          normalEquations(free);
          h = jtj;
          g = -jtr;  // the residuals here are grey - model
        },
        [&](const Vector8& v) -> std::optional<double> {
          if (!(v(kBlur) > 0.05)) return std::nullopt;
          evaluate(v, rTry, jacTry);
          clipped.censor(all(rTry));
          return cost(rTry);
        },
        [&] {
          std::swap(r, rTry);
          std::swap(jac, jacTry);
        },
        [](int it, const Vector8& step) { return it >= 1 && step.head<4>().norm() < 1e-4; }};
    // A clipped rim's levels beyond the limit come from its step's slope, slowly
    // (fitCircleProfile).
    const LevenbergMarquardtSettings settings{.maxIterations = clipped.empty() ? 15 : 40,
                                              .maxTries = 6,
                                              .initialDamping = 1e-4,
                                              .dampingDecrease = 0.3,
                                              .minDamping = 1e-9};
    return levenbergMarquardt(problem, q, settings) != LevenbergMarquardtStop::NonFiniteStep;
  };

  // Without the ramp first; the ramp only when its score test at that solution (chi-square,
  // 2 degrees of freedom, 99.9%) says the image has one: in a thin band a ramp resembles a
  // shifted rim.
  constexpr Free kNoRamp{true, true, true, true, true, false, false, true};
  constexpr Free kAll{true, true, true, true, true, true, true, true};
  if (!solve(kNoRamp)) return std::nullopt;
  bool withRamp = false;
  {
    normalEquations(kAll);
    constexpr int kRest[6] = {kCx, kCy, kRadius, kBlur, kLevel, kContrast};
    constexpr int kRamp[2] = {kRampX, kRampY};
    Eigen::Matrix<double, 6, 6> hoo;
    Eigen::Matrix<double, 2, 6> hgo;
    Eigen::Matrix2d hgg;
    Eigen::Vector2d score;
    for (int u = 0; u < 6; ++u)
      for (int v = 0; v < 6; ++v) hoo(u, v) = jtj(kRest[u], kRest[v]);
    for (int u = 0; u < 2; ++u) {
      score(u) = jtr(kRamp[u]);
      for (int v = 0; v < 2; ++v) hgg(u, v) = jtj(kRamp[u], kRamp[v]);
      for (int v = 0; v < 6; ++v) hgo(u, v) = jtj(kRamp[u], kRest[v]);
    }
    const Eigen::Matrix2d schur = hgg - hgo * hoo.ldlt().solve(hgo.transpose());
    const double statistic = score.dot(schur.ldlt().solve(score)) / std::max(sigma * sigma, 1e-12);
    if (std::isfinite(statistic) && statistic > 13.8) {
      withRamp = true;
      if (!solve(kAll)) return std::nullopt;
    }
  }

  // Sectors whose residuals stay too large for the noise leave, and the fit is repeated.
  const std::vector<std::uint8_t> bad =
      rim_band::contaminatedBins(samples, {r.data(), static_cast<std::size_t>(n)}, bins);
  Eigen::Index kept = 0;
  for (const int b : band.bin) kept += bad[static_cast<std::size_t>(b)] == 0;
  if (static_cast<double>(n - kept) >= kMinRefitShare * static_cast<double>(n)) {
    if (kept < 30) return std::nullopt;
    band.keep(bad);
    loadBand();
    if (!solve({true, true, true, true, true, withRamp, withRamp, true})) return std::nullopt;
  }

  // A sharp image: refit with each pixel's area in the model, as fitCircleProfile does.
  if (q(kBlur) < step_profile::kSharpBlur) {
    pixelModel = true;
    q(kBlur) = step_profile::lensBlurOf(q(kBlur));
    if (!solve({true, true, true, true, true, withRamp, withRamp, true})) return std::nullopt;
  }
  // A rim is a step well above the noise: a contrast within a few noise levels of none is no rim
  // (an image without contrast leaves every parameter but the level free).
  // The equivalent Gaussian blur, PSF and pixel together.
  const double blur = pixelModel ? step_profile::equivalentBlur(q(kBlur)) : q(kBlur);
  if (!q.allFinite() || std::abs(q(kContrast)) < std::max(4.0 * sigma, 1.0) || blur < 0.2 ||
      blur > 5.0 || q(kRadius) <= 0.0 || std::hypot(q(kCx), q(kCy)) > maxShiftPx ||
      std::abs(q(kRadius) - radiusPx) > maxShiftPx || !clipped.middleSeen(q(kLevel), q(kContrast)))
    return std::nullopt;
  // The 50% level of a blurred convex rim lies s^2 / (2 rho) image pixels inside it, rho the
  // rim's radius of curvature in the image: about R / k with k the plane's scale across the rim.
  const cv::Point2d c = unit * cv::Point2d(q(kCx), q(kCy));
  double scaleSum = 0.0;
  for (Eigen::Index i = 0; i < n; ++i) scaleSum += band.geometryAt(i, c, unit * q(kRadius)).scale;
  const double k = scaleSum / static_cast<double>(n);
  PlaneCircleProfileFit fit;
  fit.centreMm = centreMm + c;
  fit.radiusMm = unit * q(kRadius) + k * k * blur * blur / (2.0 * unit * q(kRadius));
  fit.blur = blur;
  fit.noise = sigma;
  fit.pixels = static_cast<int>(n);
  return fit;
}

}  // namespace facet
