// bench_circle: CircleMeasure beside cv::HoughCircles on the same generated scenes.
//
// Scenes: discs (light on dark) and holes (dark in a light plate) of radius 10..200 px at random
// subpixel centres, blur sigma 1, noise sigma 2, contrast 100; the coarse position handed to
// both methods is off by up to 2 px. Cases: clean; hard (30% of the rim occluded, clutter on the
// annulus off the rim, illumination gradient); low contrast (15 grey levels). Targets (issue 4),
// "median over >= 30 scenes per radius": centre and radius error <= 0.01 px clean, <= 0.02 px
// hard without failure, <= 0.03 px at low contrast; <= 0.5 ms at r = 100 (issue 18; issue 4 asked
// 1 ms), printed beside HOUGH_GRADIENT's time in the same run. The target column judges
// the median error over the scenes a row measured, as the issue words it; the RMS is printed
// beside it and judged too, since a median can hide a few gross errors.
//
// The bound columns are the Cramer-Rao bound (RMS) of each row for any unbiased estimator,
// computed per scene from the Fisher information of its own pixels (cramerRaoBound). A target
// below the bound is marked: no estimator meets it other than by chance.
//
// Usage: bench_circle [--smoke] [--scenes N] [--case clean|hard|low-contrast] [--radius R]
//                     [--seed N] [--verbose] [--no-grey-refinement] [--no-bias-correction]
//                     [--blur-model pixel-grid|lens]
// --blur-model: where the scenes' Gaussian acts, on the sampled image (default) or before pixel
// integration as a lens does (tests/support/scene/lens_blur.hpp; slower to render).
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
  double contrast = 0;
  bool ramp = false;  // the scene has an illumination gradient
  cv::Mat foreign;    // CV_8U, 1 where clutter or an occluder changes the noise-free grey
};

// Pixels whose noise-free grey the clutter and the occluder change by a quarter grey level or
// more: the scene rendered without noise with and without them.
cv::Mat foreignPixels(const facet::scene::Scene& scene) {
  facet::scene::SceneSpec spec = scene.spec();
  spec.noiseSigma = 0.0;
  spec.depth = CV_16U;
  facet::scene::Scene all(spec), rimOnly(spec);
  for (const auto& p : scene.primitives()) {
    all.add(p);
    if (p.role == "object" || p.role == "hole") rimOnly.add(p);
  }
  cv::Mat a, b, diff;
  all.render().convertTo(a, CV_64F, 1.0 / 256.0);
  rimOnly.render().convertTo(b, CV_64F, 1.0 / 256.0);
  cv::absdiff(a, b, diff);
  return diff >= 0.25;
}

// Where the scenes' blur acts (--blur-model lens|pixel-grid).
facet::scene::BlurModel gBlurModel = facet::scene::BlurModel::PixelGrid;

Trial makeTrial(double radius, Case kind, bool hole, int subrows, std::mt19937_64& rng) {
  std::uniform_real_distribution<double> u(0.0, 1.0);
  const int side = static_cast<int>(2 * radius + 60);
  facet::scene::SceneSpec spec;
  spec.size = {side, side};
  spec.blurSigma = 1.0;
  spec.blurModel = gBlurModel;
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
  t.contrast = contrast;
  t.ramp = kind == Case::Hard;
  t.foreign = kind == Case::Hard ? foreignPixels(scene) : cv::Mat::zeros(t.image.size(), CV_8U);
  const double ea = 2 * std::numbers::pi * u(rng), er = 2.0 * std::sqrt(u(rng));
  t.coarse = {t.centre.x + er * std::cos(ea), t.centre.y + er * std::sin(ea)};
  t.nominal = radius;
  return t;
}

double median(std::vector<double> v) {
  if (v.empty()) return NAN;
  std::sort(v.begin(), v.end());
  const std::size_t n = v.size();
  return n % 2 ? v[n / 2] : 0.5 * (v[n / 2 - 1] + v[n / 2]);
}

struct Errors {
  std::vector<double> centre, radius;  // per measured scene: |centre error|, |radius error|
  double sumKr = 0;
  int failed = 0;
  void add(cv::Point2d c, double r, const Trial& t) {
    centre.push_back(std::hypot(c.x - t.centre.x, c.y - t.centre.y));
    radius.push_back(std::abs(r - t.radius));
    sumKr += (t.radius - r) * t.radius;  // curvature-bias constant k if the error were -k/r
  }
  int measured() const { return static_cast<int>(centre.size()); }
  static double rms(const std::vector<double>& v) {
    if (v.empty()) return NAN;
    double s = 0;
    for (double e : v) s += e * e;
    return std::sqrt(s / static_cast<double>(v.size()));
  }
  double centreRms() const { return rms(centre); }
  double radiusRms() const { return rms(radius); }
  double centreMedian() const { return median(centre); }
  double radiusMedian() const { return median(radius); }
  double biasK() const { return centre.empty() ? NAN : sumKr / measured(); }
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
// The documented Canny thresholds assume about 100 grey levels of contrast: HOUGH_GRADIENT's is
// scaled with the scene's contrast, or no rim of the low-contrast case would be an edge at all.
// HOUGH_GRADIENT_ALT keeps its own: scaled, it still missed 76-100% of those circles and took
// 0.8 s per scene of r = 200 in the noise's edges.
bool hough(const Trial& t, int method, cv::Point2d* c, double* r) {
  cv::Mat img;
  std::vector<cv::Vec3f> found;
  const int minR = static_cast<int>(std::floor(t.nominal - kWidth));
  const int maxR = static_cast<int>(std::ceil(t.nominal + kWidth));
  const double contrastScale = t.contrast / 100.0;
  if (method == cv::HOUGH_GRADIENT) {
    // OpenCV tutorial: smooth first, dp 1, Canny high threshold 100, accumulator threshold low
    // enough for small circles.
    cv::GaussianBlur(t.image, img, {5, 5}, 1.5);
    cv::HoughCircles(img, found, cv::HOUGH_GRADIENT, 1, 1, 100 * contrastScale, 15,
                     std::max(minR, 1), maxR);
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
// scene, for any unbiased estimator, from the Fisher information of its pixels. Model of a pixel
// at p: I = a + g . p + b Phi(-(|p - c| - R) / s), with s^2 = blur^2 + 1/12 (PSF and pixel width)
// and white noise of variance noise^2 + 1/12 (quantisation). Unknown: c, R, s, a, b and, where
// the scene has an illumination gradient, g. Pixels: every one within 8 px of the rim (farther
// ones only pin down a and g, which are pinned already) that the clutter and the occluder leave
// unchanged. Pixels they change are left out rather than modelled, which is what an estimator
// without a model of the clutter can use.
struct Bound {
  double centre = 0, radius = 0;
};
Bound cramerRaoBound(const Trial& t) {
  const double noiseVar = 2.0 * 2.0 + 1.0 / 12.0, s = std::sqrt(1.0 + 1.0 / 12.0);
  const int params = t.ramp ? 8 : 6;
  Eigen::MatrixXd fisher = Eigen::MatrixXd::Zero(params, params);
  const double band = 8.0;
  const int x0 = std::max(0, static_cast<int>(t.centre.x - t.radius - band));
  const int x1 = std::min(t.image.cols - 1, static_cast<int>(t.centre.x + t.radius + band) + 1);
  const int y0 = std::max(0, static_cast<int>(t.centre.y - t.radius - band));
  const int y1 = std::min(t.image.rows - 1, static_cast<int>(t.centre.y + t.radius + band) + 1);
  Eigen::VectorXd j(params);
  for (int y = y0; y <= y1; ++y) {
    for (int x = x0; x <= x1; ++x) {
      const double dx = x - t.centre.x, dy = y - t.centre.y, rho = std::hypot(dx, dy);
      const double d = rho - t.radius;
      if (std::abs(d) > band || rho == 0.0 || t.foreign.at<std::uint8_t>(y, x)) continue;
      const double z = d / s;
      const double g =
          t.contrast * std::exp(-0.5 * z * z) / (std::sqrt(2.0 * std::numbers::pi) * s);
      j(0) = g * dx / rho;                              // d I / d cx
      j(1) = g * dy / rho;                              // d I / d cy
      j(2) = g;                                         // d I / d R (up to sign)
      j(3) = g * z;                                     // d I / d s
      j(4) = 1.0;                                       // d I / d a
      j(5) = 0.5 * std::erfc(z / std::numbers::sqrt2);  // d I / d b
      if (t.ramp) {
        j(6) = dx;
        j(7) = dy;
      }
      fisher.noalias() += j * j.transpose() / noiseVar;
    }
  }
  const Eigen::MatrixXd cov = fisher.inverse();
  return {std::sqrt(cov(0, 0) + cov(1, 1)), std::sqrt(cov(2, 2))};
}

}  // namespace

int main(int argc, char** argv) {
  bool smoke = false;
  // The issue asks for 30 or more. A median over 100 scenes still wanders by about +-15% between
  // seeds (hard r = 10: 0.0144 to 0.0202 px over ten seeds, 0.0170 over 8,000 scenes); over 400
  // it settles to a few percent, for about 30 s of running time.
  int scenes = 400;
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
    else if (!std::strcmp(argv[i], "--blur-model") && i + 1 < argc) {
      const std::string m = argv[++i];
      if (m != "lens" && m != "pixel-grid") {
        std::fprintf(stderr, "bench_circle: --blur-model must be lens or pixel-grid\n");
        return 2;
      }
      gBlurModel = m == "lens" ? facet::scene::BlurModel::Lens : facet::scene::BlurModel::PixelGrid;
    } else {
      std::fprintf(stderr, "bench_circle: unknown argument %s\n", argv[i]);
      return 2;
    }
  }
  if (smoke) scenes = 2;
  const int subrows = smoke ? 32 : 256;
  cv::setNumThreads(1);

  const double radii[] = {10, 20, 50, 100, 200};
  std::printf(
      "bench_circle: %d scenes per radius and case (half discs, half holes), blur 1 (%s model), "
      "noise 2, seed %llu%s\n",
      scenes, facet::scene::blurModelName(gBlurModel), static_cast<unsigned long long>(seed),
      smoke ? " [smoke]" : "");
  std::printf(
      "errors in px over the scenes measured: |centre error| (2D) and |radius error|; fail = no "
      "result\n"
      "bound = Cramer-Rao bound (RMS) from each scene's pixels within 8 px of the rim that "
      "clutter and\n"
      "occluder leave unchanged; levels, blur (and the illumination ramp in the hard case) "
      "unknown.\n"
      "At the bound, an unbiased estimator's median error is about 0.83 x bound (centre, 2D) and "
      "0.67 x bound\n"
      "(radius). MISSED* = the target lies below that: no estimator meets it but by chance\n\n");

  struct Row {
    Case kind;
    double radius;
    Errors ours, hg, alt;
    Bound bound;
  };
  std::vector<Row> rows;
  for (Case kind : {Case::Clean, Case::Hard, Case::LowContrast}) {
    if (!onlyCase.empty() && onlyCase != caseName(kind)) continue;
    for (double radius : radii) {
      if (onlyRadius > 0 && radius != onlyRadius) continue;
      std::mt19937_64 rng(static_cast<std::uint64_t>(radius * 1000) + static_cast<int>(kind) +
                          seed * 1000003);
      Row row{kind, radius, {}, {}, {}, {}};
      double boundC2 = 0, boundR2 = 0;
      for (int s = 0; s < scenes; ++s) {
        const Trial t = makeTrial(radius, kind, s % 2 == 1, subrows, rng);
        const facet::CircleMeasurement m = facet::measureCircle(t.image, paramsFor(t));
        if (m.status.ok())
          row.ours.add(m.centre, m.radius, t);
        else
          ++row.ours.failed;
        const Bound b = cramerRaoBound(t);
        boundC2 += b.centre * b.centre;
        boundR2 += b.radius * b.radius;
        if (gVerbose)
          std::printf(
              "  %s r=%.0f scene %d %s: %s c err (%.4f, %.4f) r err %.4f inliers %d/%d "
              "cov %.0f rms %.3f refined %d bound c %.4f %s\n",
              caseName(kind), radius, s, t.hole ? "hole" : "disc",
              m.status.ok() ? "ok" : std::string(facet::toString(m.status.cause)).c_str(),
              m.centre.x - t.centre.x, m.centre.y - t.centre.y, m.radius - t.radius, m.inliers,
              m.candidates, m.coverageDeg, m.rms, m.greyRefined, b.centre,
              m.status.message.c_str());
        cv::Point2d c;
        double r = 0;
        if (hough(t, cv::HOUGH_GRADIENT, &c, &r))
          row.hg.add(c, r, t);
        else
          ++row.hg.failed;
        if (hough(t, cv::HOUGH_GRADIENT_ALT, &c, &r))
          row.alt.add(c, r, t);
        else
          ++row.alt.failed;
      }
      row.bound = {std::sqrt(boundC2 / scenes), std::sqrt(boundR2 / scenes)};
      rows.push_back(std::move(row));
    }
  }

  // Accuracy against the targets.
  std::printf("%-12s %5s | %8s %8s | %8s %8s | %4s | %7s %7s | %-10s | %-8s | %-8s | %s\n", "case",
              "r", "median c", "median r", "RMS c", "RMS r", "fail", "bound c", "bound r", "target",
              "median", "RMS", "k");
  bool allMedian = true, allRms = true;
  for (const Row& row : rows) {
    const Errors& o = row.ours;
    const double target = 0.01 * caseFactor(row.kind);
    const bool none = o.failed == 0;
    const bool medianMet = none && o.centreMedian() <= target && o.radiusMedian() <= target;
    const bool rmsMet = none && o.centreRms() <= target && o.radiusRms() <= target;
    const bool medianBelow = 0.833 * row.bound.centre > target || 0.674 * row.bound.radius > target;
    const bool rmsBelow = row.bound.centre > target || row.bound.radius > target;
    allMedian = allMedian && medianMet;
    allRms = allRms && rmsMet;
    auto verdict = [](bool met, bool below) { return met ? "met" : below ? "MISSED*" : "MISSED"; };
    char targetText[16];
    std::snprintf(targetText, sizeof targetText, "<= %.2f", target);
    std::printf(
        "%-12s %5.0f | %8.4f %8.4f | %8.4f %8.4f | %4d | %7.4f %7.4f | %-10s | %-8s | %-8s | "
        "%.3f\n",
        caseName(row.kind), row.radius, o.centreMedian(), o.radiusMedian(), o.centreRms(),
        o.radiusRms(), o.failed, row.bound.centre, row.bound.radius, targetText,
        verdict(medianMet, medianBelow), verdict(rmsMet, rmsBelow), o.biasK());
  }

  // The same scenes through HoughCircles: RMS errors and the ratio to ours.
  std::printf("\n%-12s %5s | %8s %8s %4s | %8s %8s %4s | %6s %6s %6s %6s\n", "case", "r", "HG c",
              "HG r", "miss", "ALT c", "ALT r", "miss", "HG/c", "HG/r", "ALT/c", "ALT/r");
  for (const Row& row : rows) {
    const Errors &o = row.ours, &hg = row.hg, &alt = row.alt;
    std::printf("%-12s %5.0f | %8.4f %8.4f %4d | %8.4f %8.4f %4d | %6.1f %6.1f %6.1f %6.1f\n",
                caseName(row.kind), row.radius, hg.centreRms(), hg.radiusRms(), hg.failed,
                alt.centreRms(), alt.radiusRms(), alt.failed, hg.centreRms() / o.centreRms(),
                hg.radiusRms() / o.radiusRms(), alt.centreRms() / o.centreRms(),
                alt.radiusRms() / o.radiusRms());
  }
  std::printf(
      "(HG = HOUGH_GRADIENT, ALT = HOUGH_GRADIENT_ALT: RMS errors over the scenes each detected "
      "a circle within the search width; miss = none; ratio = hough RMS / ours)\n");

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
    if (!m.status.ok()) std::printf("timing scene failed: %s\n", m.status.message.c_str());
    ours.push_back(t1 - t0);
    hgT.push_back(t2 - t1);
    altT.push_back(t3 - t2);
  }
  const double ms = median(ours);
  std::printf(
      "\ntime per circle r=100 (%dx%d image, median of %d, thread CPU time): ours %.3f ms | "
      "HOUGH_GRADIENT %.3f ms | HOUGH_GRADIENT_ALT %.3f ms | ours / HOUGH_GRADIENT %.2f | target "
      "<= 0.5 ms: %s\n",
      t.image.cols, t.image.rows, reps, ms, median(hgT), median(altT), ms / median(hgT),
      ms <= 0.5 ? "met" : "MISSED");
  std::printf("accuracy targets by the median (the issue's statistic): %s; by the RMS: %s\n",
              allMedian ? "all met" : "NOT all met", allRms ? "all met" : "NOT all met");
  return 0;
}
