// bench_circle: CircleMeasure beside cv::HoughCircles on the same generated scenes.
//
// Scenes: discs (light on dark) and holes (dark in a light plate) of radius 10..200 px at random
// subpixel centres, blur sigma 1, noise sigma 2, contrast 100; the coarse position handed to
// both methods is off by up to 2 px. Cases: clean; hard (30% of the rim occluded, clutter on the
// annulus off the rim, illumination gradient); low contrast (15 grey levels). Errors are RMS over
// the scenes a method measured; failures are counted separately. Targets (issue 4): clean centre
// and radius RMS <= 0.01 px, hard <= 0.02 px without failure, low contrast <= 0.03 px, <= 1 ms at r
// = 100. The CRLB columns give the Cramer-Rao bound of each case (cramerRaoBound).
//
// Usage: bench_circle [--smoke] [--scenes N] [--case clean|hard|low-contrast] [--radius R]
//                     [--seed N] [--verbose] [--no-grey-refinement] [--no-bias-correction]
// --seed N (default 0) draws other scenes: the accuracy must not depend on one set of scenes.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <ctime>
#include <numbers>
#include <random>
#include <string>
#include <vector>

#include <Eigen/Dense>
#include <opencv2/imgproc.hpp>

#include "algorithms/circle/circle_measure.hpp"
#include "tests/support/scene/scene.hpp"

namespace {

// Thread CPU time: "one core" is what the target means, and the machine is shared, so wall time
// would measure the other processes too.
double cpuMs() {
  timespec t{};
  clock_gettime(CLOCK_THREAD_CPUTIME_ID, &t);
  return t.tv_sec * 1e3 + t.tv_nsec * 1e-6;
}

enum class Case { Clean, Hard, LowContrast };
const char* caseName(Case c) {
  return c == Case::Clean ? "clean" : c == Case::Hard ? "hard" : "low-contrast";
}
double caseFactor(Case c) {
  return c == Case::Clean ? 1.0 : c == Case::Hard ? 2.0 : 3.0;
}

struct Trial {
  cv::Mat image;
  cv::Point2d centre;  // truth
  double radius = 0;   // truth
  cv::Point2d coarse;  // what the measurement is given
  double nominal = 0;
  bool hole = false;
};

Trial makeTrial(double radius, Case kind, bool hole, int subrows, std::mt19937_64& rng) {
  std::uniform_real_distribution<double> u(0.0, 1.0);
  const int side = static_cast<int>(2 * radius + 60);
  facet::scene::SceneSpec spec;
  spec.size = {side, side};
  spec.blurSigma = 1.0;
  spec.noiseSigma = 2.0;
  spec.subrows = subrows;
  spec.seed = rng();
  const double contrast = kind == Case::LowContrast ? 15.0 : 100.0;
  const double dark = 70.0, light = dark + contrast;
  spec.background = hole ? light : dark;
  if (kind == Case::Hard) {
    const double a = 2 * std::numbers::pi * u(rng);
    // Up to 60 grey levels across the image, whatever its size.
    spec.illuminationGradient = {60.0 / side * std::cos(a), 60.0 / side * std::sin(a)};
  }
  Trial t;
  t.hole = hole;
  t.centre = {(side - 1) / 2.0 + u(rng) - 0.5, (side - 1) / 2.0 + u(rng) - 0.5};
  t.radius = radius + 0.6 * (u(rng) - 0.5);
  facet::scene::Scene scene(spec);
  scene.addDisc(t.centre, t.radius, hole ? dark : light, hole ? "hole" : "object");
  if (kind == Case::Hard) {
    const cv::Rect2d box{t.centre.x - t.radius, t.centre.y - t.radius, 2 * t.radius, 2 * t.radius};
    scene.addClutter(6, 4.0, 0.3 * radius + 4.0, {box}, 0.0, 255.0);
    // Clutter inside the annulus but off the rim: small blobs 3 to 4.5 px inside or outside it,
    // at least 1.5 px clear of the rim (what covers the rim is the occluder's job).
    const int blobs = 3;
    for (int i = 0; i < blobs; ++i) {
      const double a = 2 * std::numbers::pi * u(rng);
      const double off = (u(rng) < 0.5 ? -1.0 : 1.0) * (3.0 + 1.5 * u(rng));
      const double rr = t.radius + off;
      scene.addDisc({t.centre.x + rr * std::cos(a), t.centre.y + rr * std::sin(a)},
                    0.7 + (std::abs(off) - 2.2) * u(rng), 255.0 * u(rng), "clutter");
    }
    // A strip covering 20.6% of the box from one side hides 30% of the rim (cos 54 deg).
    scene.addOccluder(box, 0.206, 100.0 + 60.0 * u(rng));
  }
  t.image = scene.render();
  const double ea = 2 * std::numbers::pi * u(rng), er = 2.0 * std::sqrt(u(rng));
  t.coarse = {t.centre.x + er * std::cos(ea), t.centre.y + er * std::sin(ea)};
  t.nominal = radius;
  return t;
}

struct Errors {
  double sumC2 = 0, sumR2 = 0, sumKr = 0;
  int measured = 0, failed = 0;
  void add(cv::Point2d c, double r, const Trial& t) {
    sumC2 += std::pow(c.x - t.centre.x, 2) + std::pow(c.y - t.centre.y, 2);
    sumR2 += std::pow(r - t.radius, 2);
    sumKr += (t.radius - r) * t.radius;  // curvature-bias constant k if the error were -k/r
    ++measured;
  }
  double centreRms() const { return measured ? std::sqrt(sumC2 / measured) : NAN; }
  double radiusRms() const { return measured ? std::sqrt(sumR2 / measured) : NAN; }
  double biasK() const { return measured ? sumKr / measured : NAN; }
};

constexpr double kWidth = 5.0;
bool gCorrectBias = true;
bool gGreyRefinement = true;
bool gVerbose = false;

facet::CircleMeasureParams paramsFor(const Trial& t) {
  facet::CircleMeasureParams p;
  p.centre = t.coarse;
  p.radius = t.nominal;
  p.width = kWidth;
  p.correctRadiusBias = gCorrectBias;
  p.refineWithGreyValues = gGreyRefinement;
  p.polarity = t.hole ? facet::CirclePolarity::DarkToLight : facet::CirclePolarity::LightToDark;
  return p;
}

// HoughCircles with the documented settings, restricted to the same radius range; the detection
// strongest within the search width of the coarse position counts (the caller knows where to look).
bool hough(const Trial& t, int method, cv::Point2d* c, double* r) {
  cv::Mat img;
  std::vector<cv::Vec3f> found;
  const int minR = static_cast<int>(std::floor(t.nominal - kWidth));
  const int maxR = static_cast<int>(std::ceil(t.nominal + kWidth));
  if (method == cv::HOUGH_GRADIENT) {
    // OpenCV tutorial: smooth first, dp 1, Canny high threshold 100, accumulator threshold low
    // enough for small circles.
    cv::GaussianBlur(t.image, img, {5, 5}, 1.5);
    cv::HoughCircles(img, found, cv::HOUGH_GRADIENT, 1, 1, 100, 15, std::max(minR, 1), maxR);
  } else {
    // Documentation of HOUGH_GRADIENT_ALT: dp 1.5, param1 300, param2 0.9 (circle "perfectness").
    cv::HoughCircles(t.image, found, cv::HOUGH_GRADIENT_ALT, 1.5, 1, 300, 0.9, std::max(minR, 1),
                     maxR);
  }
  // Detections come strongest first: take the strongest one within the search width.
  for (const auto& f : found) {
    if (std::hypot(f[0] - t.coarse.x, f[1] - t.coarse.y) <= kWidth) {
      *c = {f[0], f[1]};
      *r = f[2];
      return true;
    }
  }
  return false;
}

// Cramer-Rao bound of the centre error (RMS of the 2D distance) and of the radius error of one
// scene of the case, for any unbiased estimator, from the Fisher information of the pixels.
// Model of a pixel at p: I = a + g . p + b Phi(-(|p - c| - R) / s), with s^2 = blur^2 + 1/12
// (PSF and pixel width) and white noise of variance noise^2 + 1/12 (quantisation). Unknown: c, R,
// s, a, b and, in the hard case (which has an illumination gradient), g. Pixels: every one within
// 8 px of the rim (farther ones only pin down a and g, which are pinned already); in the hard
// case minus the strip of the occluder over 30% of the rim. The clutter is left out, which can
// only lower the bound. Centre (0.3, 0.2) px off the pixel grid.
struct Bound {
  double centre = 0, radius = 0;
};
Bound cramerRaoBound(double radius, Case kind) {
  const double contrast = kind == Case::LowContrast ? 15.0 : 100.0;
  const double noiseVar = 2.0 * 2.0 + 1.0 / 12.0, s = std::sqrt(1.0 + 1.0 / 12.0);
  const bool hard = kind == Case::Hard;
  const int params = hard ? 8 : 6;
  Eigen::MatrixXd fisher = Eigen::MatrixXd::Zero(params, params);
  const double cx = 0.3, cy = 0.2, band = 8.0;
  const int n = static_cast<int>(radius + band) + 2;
  for (int y = -n; y <= n; ++y) {
    for (int x = -n; x <= n; ++x) {
      const double dx = x - cx, dy = y - cy, rho = std::hypot(dx, dy), d = rho - radius;
      if (std::abs(d) > band || rho == 0.0) continue;
      // The occluder strip of the bench: x from 0.588 R to R + 2, |y| up to R + 2.
      if (hard && dx >= 0.588 * radius && dx <= radius + 2.0 && std::abs(dy) <= radius + 2.0)
        continue;
      const double z = d / s;
      const double g = contrast * std::exp(-0.5 * z * z) / (std::sqrt(2.0 * std::numbers::pi) * s);
      Eigen::VectorXd j(params);
      j(0) = g * dx / rho;                              // d I / d cx
      j(1) = g * dy / rho;                              // d I / d cy
      j(2) = g;                                         // d I / d R (up to sign)
      j(3) = g * z;                                     // d I / d s
      j(4) = 1.0;                                       // d I / d a
      j(5) = 0.5 * std::erfc(z / std::numbers::sqrt2);  // d I / d b
      if (hard) {
        j(6) = dx;
        j(7) = dy;
      }
      fisher.noalias() += j * j.transpose() / noiseVar;
    }
  }
  const Eigen::MatrixXd cov = fisher.inverse();
  return {std::sqrt(cov(0, 0) + cov(1, 1)), std::sqrt(cov(2, 2))};
}

double medianMs(std::vector<double> v) {
  std::sort(v.begin(), v.end());
  return v[v.size() / 2];
}

}  // namespace

int main(int argc, char** argv) {
  bool smoke = false;
  int scenes = 30;
  std::string onlyCase;    // --case clean|hard|low-contrast: that case alone
  double onlyRadius = 0;   // --radius R: that radius alone
  std::uint64_t seed = 0;  // --seed N: another set of scenes (0: the original ones)
  for (int i = 1; i < argc; ++i) {
    if (!std::strcmp(argv[i], "--smoke"))
      smoke = true;
    else if (!std::strcmp(argv[i], "--no-bias-correction"))
      gCorrectBias = false;
    else if (!std::strcmp(argv[i], "--verbose"))
      gVerbose = true;
    else if (!std::strcmp(argv[i], "--no-grey-refinement"))
      gGreyRefinement = false;
    else if (!std::strcmp(argv[i], "--scenes") && i + 1 < argc)
      scenes = std::atoi(argv[++i]);
    else if (!std::strcmp(argv[i], "--case") && i + 1 < argc)
      onlyCase = argv[++i];
    else if (!std::strcmp(argv[i], "--radius") && i + 1 < argc)
      onlyRadius = std::atof(argv[++i]);
    else if (!std::strcmp(argv[i], "--seed") && i + 1 < argc)
      seed = std::strtoull(argv[++i], nullptr, 10);
  }
  if (smoke) scenes = 2;
  const int subrows = smoke ? 32 : 256;
  cv::setNumThreads(1);

  const double radii[] = {10, 20, 50, 100, 200};
  std::printf(
      "bench_circle: %d scenes per radius and case (half discs, half holes), blur 1, noise 2, "
      "seed %llu%s\n",
      scenes, static_cast<unsigned long long>(seed), smoke ? " [smoke]" : "");
  std::printf(
      "errors are RMS in px over measured scenes; fail = no result; ratio = hough / ours\n\n");
  std::printf(
      "CRLB c / r = Cramer-Rao bound of the centre / radius error of any unbiased estimator: all\n"
      "pixels within 8 px of the visible rim, blur 1, noise 2, quantisation, levels, blur (and "
      "the\n"
      "illumination ramp in the hard case) unknown; clutter left out. MISSED* = the target lies\n"
      "below the bound (no unbiased estimator meets it)\n\n");
  std::printf(
      "%-12s %5s | %8s %8s %4s | %7s %7s | %8s %8s %4s | %8s %8s %4s | %6s %6s %6s %6s | %-17s | "
      "%s\n",
      "case", "r", "ours c", "ours r", "fail", "CRLB c", "CRLB r", "HG c", "HG r", "miss", "ALT c",
      "ALT r", "miss", "HG/c", "HG/r", "ALT/c", "ALT/r", "target", "k");
  bool allMet = true;
  for (Case kind : {Case::Clean, Case::Hard, Case::LowContrast}) {
    if (!onlyCase.empty() && onlyCase != caseName(kind)) continue;
    for (double radius : radii) {
      if (onlyRadius > 0 && radius != onlyRadius) continue;
      std::mt19937_64 rng(static_cast<std::uint64_t>(radius * 1000) + static_cast<int>(kind) +
                          seed * 1000003);
      Errors ours, hg, alt;
      for (int s = 0; s < scenes; ++s) {
        const Trial t = makeTrial(radius, kind, s % 2 == 1, subrows, rng);
        const facet::CircleMeasurement m = facet::measureCircle(t.image, paramsFor(t));
        if (m.ok())
          ours.add(m.centre, m.radius, t);
        else
          ++ours.failed;
        if (gVerbose)
          std::printf(
              "  %s r=%.0f scene %d %s: %s c err (%.4f, %.4f) r err %.4f inliers %d/%d "
              "cov %.0f rms %.3f refined %d %s\n",
              caseName(kind), radius, s, t.hole ? "hole" : "disc",
              m.ok() ? "ok" : facet::circleFailureCause(m.failures).c_str(),
              m.centre.x - t.centre.x, m.centre.y - t.centre.y, m.radius - t.radius, m.inliers,
              m.candidates, m.coverageDeg, m.rms, m.greyRefined, m.message.c_str());
        cv::Point2d c;
        double r = 0;
        if (hough(t, cv::HOUGH_GRADIENT, &c, &r))
          hg.add(c, r, t);
        else
          ++hg.failed;
        if (hough(t, cv::HOUGH_GRADIENT_ALT, &c, &r))
          alt.add(c, r, t);
        else
          ++alt.failed;
      }
      const double bound = 0.01 * caseFactor(kind);
      const bool met = ours.failed == 0 && ours.centreRms() <= bound && ours.radiusRms() <= bound;
      allMet = allMet && met;
      const Bound crlb = cramerRaoBound(radius, kind);
      const bool belowBound = crlb.centre > bound || crlb.radius > bound;
      std::printf(
          "%-12s %5.0f | %8.4f %8.4f %4d | %7.4f %7.4f | %8.4f %8.4f %4d | %8.4f %8.4f %4d | %6.1f "
          "%6.1f %6.1f %6.1f | %7s (<= %.2f) | %.3f\n",
          caseName(kind), radius, ours.centreRms(), ours.radiusRms(), ours.failed, crlb.centre,
          crlb.radius, hg.centreRms(), hg.radiusRms(), hg.failed, alt.centreRms(), alt.radiusRms(),
          alt.failed, hg.centreRms() / ours.centreRms(), hg.radiusRms() / ours.radiusRms(),
          alt.centreRms() / ours.centreRms(), alt.radiusRms() / ours.radiusRms(),
          met          ? "met"
          : belowBound ? "MISSED*"
                       : "MISSED",
          bound, ours.biasK());
    }
  }

  // Time per circle at r = 100 after the coarse location, one core.
  std::mt19937_64 rng(7);
  const Trial t = makeTrial(100, Case::Clean, false, subrows, rng);
  const int reps = smoke ? 20 : 200;
  std::vector<double> ours, hgT, altT;
  for (int i = 0; i < reps; ++i) {
    const double t0 = cpuMs();
    const auto m = facet::measureCircle(t.image, paramsFor(t));
    const double t1 = cpuMs();
    cv::Point2d c;
    double r;
    hough(t, cv::HOUGH_GRADIENT, &c, &r);
    const double t2 = cpuMs();
    hough(t, cv::HOUGH_GRADIENT_ALT, &c, &r);
    const double t3 = cpuMs();
    if (!m.ok()) std::printf("timing scene failed: %s\n", m.message.c_str());
    ours.push_back(t1 - t0);
    hgT.push_back(t2 - t1);
    altT.push_back(t3 - t2);
  }
  const double ms = medianMs(ours);
  std::printf(
      "\ntime per circle r=100 (%dx%d image, median of %d, thread CPU time): ours %.3f ms | "
      "HOUGH_GRADIENT %.3f ms | HOUGH_GRADIENT_ALT %.3f ms | target <= 1 ms: %s\n",
      t.image.cols, t.image.rows, reps, ms, medianMs(hgT), medianMs(altT),
      ms <= 1.0 ? "met" : "MISSED");
  std::printf("all accuracy targets %s\n", allMet ? "met" : "NOT met");
  return 0;
}
