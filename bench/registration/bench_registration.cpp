// bench_registration: log-polar feature registration against OpenCV SIFT on the Oxford graf
// sequence (and the other Oxford sequences in the repository), synthetic similarity pairs from
// graf img1, defocused copies of Oxford views, photographs from Debian's opencv-doc under
// synthetic homographies, and the NCC accelerations.
//
//   bench_registration [--smoke] [--data DIR] [--synthetic N] [--photos A.jpg,B.png,...]
// --photos runs only the photograph table, on those files of opencv-doc's examples/data (a set
// of one's own choosing, beside the tuned and held-out ones).
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <ctime>
#include <fstream>
#include <optional>
#include <random>
#include <sstream>
#include <string>
#include <utility>
#include <vector>

#include <opencv2/calib3d.hpp>
#include <opencv2/features2d.hpp>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <opencv2/video/tracking.hpp>

#include "algorithms/image/grey_image.hpp"
#include "algorithms/registration/harris_corners.hpp"
#include "algorithms/registration/log_polar_window.hpp"
#include "algorithms/registration/ncc_matcher.hpp"
#include "algorithms/registration/register_images.hpp"

namespace {

// An image as `facet register` reads it: decoded as stored, colour turned grey by toGrey
// (cv::cvtColor's weights). cv::imread's IMREAD_GRAYSCALE converts inside the PNG or JPEG
// decoder with other rounding, +-1 grey level: enough to turn graf 1-6 from registered to
// refused before the runners-up (register_images.hpp), so the table reads what users get.
cv::Mat readGrey(const std::string& path) {
  return facet::toGrey(cv::imread(path, cv::IMREAD_UNCHANGED));
}

// Time is the calling thread's CPU time: the machine is shared by many jobs, and wall time
// there measures the neighbours as much as the code. Everything here runs single-threaded
// (cv::setNumThreads(1) in main), SIFT included.
struct CpuTime {
  double ms = 0;
};
CpuTime cpuNow() {
  timespec t{};
  clock_gettime(CLOCK_THREAD_CPUTIME_ID, &t);
  return {t.tv_sec * 1e3 + t.tv_nsec * 1e-6};
}
double msSince(CpuTime t0) {
  return cpuNow().ms - t0.ms;
}

// Each pair's image noise comes from its own seed, so that a table's figures do not depend on
// what the tables before it drew from OpenCV's global generator.
cv::Mat pairNoise(cv::Size size, double sigma, std::uint64_t seed) {
  cv::Mat noise(size, CV_16S);
  cv::RNG rng(seed);
  rng.fill(noise, cv::RNG::NORMAL, 0, sigma);
  return noise;
}

std::uint64_t pairSeed(const std::string& photo, std::uint64_t warp) {
  std::uint64_t h = 1469598103934665603ull;  // FNV-1a: the same on every platform
  for (const unsigned char ch : photo) h = (h ^ ch) * 1099511628211ull;
  return h + warp;
}

cv::Matx33d readHomography(const std::string& path) {
  std::ifstream in(path);
  cv::Matx33d H;
  for (int k = 0; k < 9; ++k)
    if (!(in >> H(k / 3, k % 3))) {
      std::fprintf(stderr, "bench_registration: cannot read homography %s\n", path.c_str());
      std::exit(1);
    }
  return H;
}

double cornerError(const cv::Matx33d& est, const cv::Matx33d& truth, cv::Size size) {
  const cv::Point2d corners[4] = {
      {0, 0}, {size.width - 1.0, 0}, {size.width - 1.0, size.height - 1.0}, {0, size.height - 1.0}};
  double sum = 0;
  for (const auto& c : corners) {
    const cv::Point2d a = facet::mapPoint(est, c), b = facet::mapPoint(truth, c);
    const double d = std::hypot(a.x - b.x, a.y - b.y);
    sum += std::isfinite(d) ? d : 1e9;
  }
  return sum / 4;
}

// A second reference for a pair: the homography at which the two photographs agree best pixel
// by pixel (OpenCV's ECC, every pixel of the overlap, started from the published H), with the
// finer of the two low-passed to the other's scale (sigma 0.5 sqrt(r^2 - 1) px for a ratio r) so
// that both carry the same detail. The published homographies come from hand-picked points and
// claim about a pixel; a pair's estimators can only be ranked where the reference is better than
// their differences. Meaningful only where the images differ by the homography, blur and noise
// (zoom, rotation, blur): not under a change of light or a viewpoint that changes the local
// scale across the image. Not facet's code, so it judges facet and SIFT alike.
struct DenseReference {
  cv::Matx33d H;
  double correlation = 0;  // ECC's final correlation coefficient over the overlap
};

std::optional<DenseReference> denseReference(const cv::Mat& img1, const cv::Mat& imgN,
                                             const cv::Matx33d& published) {
  // The ratio of scales from the published H's Jacobian at img1's centre.
  const cv::Point2d c((img1.cols - 1) / 2.0, (img1.rows - 1) / 2.0);
  const cv::Vec3d p = published * cv::Vec3d(c.x, c.y, 1.0);
  cv::Matx22d jac;
  for (int r = 0; r < 2; ++r)
    for (int k = 0; k < 2; ++k)
      jac(r, k) = (published(r, k) * p[2] - p[r] * published(2, k)) / (p[2] * p[2]);
  const double ratio = std::sqrt(std::abs(cv::determinant(jac)));  // imgN px per img1 px
  cv::Mat fixed, moving;
  img1.convertTo(fixed, CV_32F);
  imgN.convertTo(moving, CV_32F);
  if (ratio > 1.05)
    cv::GaussianBlur(moving, moving, {0, 0}, 0.5 * std::sqrt(ratio * ratio - 1));
  else if (ratio < 1 / 1.05)
    cv::GaussianBlur(fixed, fixed, {0, 0}, 0.5 * std::sqrt(1 / (ratio * ratio) - 1));
  cv::Mat warp;
  cv::Mat(published * (1.0 / published(2, 2))).convertTo(warp, CV_32F);
  DenseReference d;
  try {
    d.correlation = cv::findTransformECC(
        fixed, moving, warp, cv::MOTION_HOMOGRAPHY,
        {cv::TermCriteria::COUNT | cv::TermCriteria::EPS, 200, 1e-7}, cv::noArray(), 5);
  } catch (const cv::Exception&) {
    return std::nullopt;  // ECC did not converge
  }
  cv::Matx33f h = warp;
  d.H = cv::Matx33d(h) * (1.0 / h(2, 2));
  return d;
}

struct Outcome {
  int matches = 0, correct = 0, inliers = 0;
  double cornerError = 1e9, ms = 0;
  double uncertainty = 0;  // facet: how far it says the overlap may be off (1 sigma, px)
  bool ok = false;
  cv::Matx33d H;        // the estimate, when ok
  std::string stage;    // facet: the stage whose result counts ("+" = after the plain one)
  std::string failure;  // facet: why no transform was found
};

Outcome runOurs(const cv::Mat& a, const cv::Mat& b, const cv::Matx33d& truth,
                const facet::RegistrationParams& params) {
  const CpuTime t0 = cpuNow();
  const facet::RegistrationResult r = facet::registerImages(a, b, params);
  Outcome o;
  o.ms = msSince(t0);
  o.matches = static_cast<int>(r.matches.size());
  for (const auto& m : r.matches) {
    const cv::Point2d q = facet::mapPoint(truth, m.ref);
    if (std::hypot(q.x - m.image.x, q.y - m.image.y) < 3.0) ++o.correct;
  }
  o.ok = r.status.ok();
  o.stage = r.stage + (r.escalated ? "+" : "");
  if (!r.status.ok())
    o.failure = std::string(facet::toString(r.status.cause)) + ": " + r.status.message;
  if (r.status.ok()) {
    o.inliers = static_cast<int>(r.inliers.size());
    o.cornerError = cornerError(r.H, truth, a.size());
    o.uncertainty = r.overlapUncertainty;
    o.H = r.H;
  }
  return o;
}

Outcome runSift(const cv::Mat& a, const cv::Mat& b, const cv::Matx33d& truth) {
  const CpuTime t0 = cpuNow();
  cv::Ptr<cv::SIFT> sift = cv::SIFT::create();
  std::vector<cv::KeyPoint> ka, kb;
  cv::Mat da, db;
  sift->detectAndCompute(a, cv::noArray(), ka, da);
  sift->detectAndCompute(b, cv::noArray(), kb, db);
  cv::BFMatcher matcher(cv::NORM_L2);
  std::vector<std::vector<cv::DMatch>> knn;
  if (!da.empty() && !db.empty()) matcher.knnMatch(da, db, knn, 2);
  std::vector<cv::Point2f> pa, pb;
  for (const auto& m : knn)
    if (m.size() == 2 && m[0].distance < 0.8f * m[1].distance) {
      pa.push_back(ka[m[0].queryIdx].pt);
      pb.push_back(kb[m[0].trainIdx].pt);
    }
  cv::Mat mask;
  cv::Mat H;
  if (pa.size() >= 4) H = cv::findHomography(pa, pb, cv::RANSAC, 3.0, mask);
  Outcome o;
  o.ms = msSince(t0);
  o.matches = static_cast<int>(pa.size());
  for (std::size_t i = 0; i < pa.size(); ++i) {
    const cv::Point2d q = facet::mapPoint(truth, cv::Point2d(pa[i]));
    if (std::hypot(q.x - pb[i].x, q.y - pb[i].y) < 3.0) ++o.correct;
  }
  if (!H.empty()) {
    o.ok = true;
    o.inliers = cv::countNonZero(mask);
    o.cornerError = cornerError(cv::Matx33d(H), truth, a.size());
    o.H = cv::Matx33d(H);
  }
  return o;
}

// The defaults, as `facet register` runs without flags: plain Harris first, Harris-Affine
// regions when that stage finds no transform to stand on.
facet::RegistrationParams grafParams() {
  return {};
}

// One Oxford sequence: img1 against each later view, facet's defaults beside SIFT.
void sequenceTable(const std::string& dir, const std::string& name, const char* change, bool smoke,
                   int repeats, bool withGlobalStage, bool withDenseReference) {
  const cv::Mat img1 = readGrey(dir + "/img1.png");
  if (img1.empty()) {
    std::fprintf(stderr, "bench_registration: cannot read %s/img1.png\n", dir.c_str());
    std::exit(1);
  }
  std::printf(
      "\n== Oxford %s (%s): img1 -> imgN (correct = match within 3 px under the true H; "
      "corner error = mean |H_est - H_true| over img1's corners;\n   ms = thread CPU time, best of "
      "%d runs, both single-threaded) ==\n",
      name.c_str(), change, repeats);
  std::printf("%-5s | %7s %7s %8s %8s %-15s | %7s %7s %8s %8s | %8s %8s %s\n", "pair", "correct",
              "inliers", "corner", "ms", "stage", "correct", "inliers", "corner", "ms", "correct",
              "time", "");
  std::printf("%-5s | %-49s | %-33s | %-17s |\n", "",
              "facet defaults (stage; + = after the plain Harris one)",
              "OpenCV SIFT (ratio 0.8 + RANSAC 3)", "facet / SIFT");
  const int last = smoke ? 3 : 6;
  int met = 0;
  double oursMs = 0, siftMs = 0;
  struct PairRun {
    cv::Mat imgN;
    cv::Matx33d truth;
    Outcome ours, sift;
  };
  std::vector<PairRun> runs;  // per pair, for the dense reference below
  for (int n = 2; n <= last; ++n) {
    const cv::Mat imgN = readGrey(dir + "/img" + std::to_string(n) + ".png");
    const cv::Matx33d truth = readHomography(dir + "/H1to" + std::to_string(n) + "p");
    // Best of `repeats` runs each, alternating, so that both see the same machine.
    Outcome ours = runOurs(img1, imgN, truth, grafParams());
    Outcome sift = runSift(img1, imgN, truth);
    for (int k = 1; k < repeats; ++k) {
      ours.ms = std::min(ours.ms, runOurs(img1, imgN, truth, grafParams()).ms);
      sift.ms = std::min(sift.ms, runSift(img1, imgN, truth).ms);
    }
    const bool siftSolves = sift.ok && sift.cornerError <= 3.0;
    const bool good = ours.ok && ours.correct > sift.correct && ours.cornerError <= 3.0 &&
                      (!siftSolves || ours.cornerError <= sift.cornerError) && ours.ms <= sift.ms;
    met += good;
    oursMs += ours.ms;
    siftMs += sift.ms;
    std::printf("1-%d   | %7d %7d %8.2f %8.1f %-15s | %7d %7d %8.2f %8.1f | %8.2f %8.2f %s\n", n,
                ours.correct, ours.inliers, ours.ok ? ours.cornerError : -1, ours.ms,
                ours.stage.c_str(), sift.correct, sift.inliers, sift.ok ? sift.cornerError : -1,
                sift.ms, sift.correct > 0 ? double(ours.correct) / sift.correct : 0.0,
                ours.ms / sift.ms, good ? "target met" : "TARGET MISSED");
    if (!ours.ok) std::printf("  facet found no transform: %s\n", ours.failure.c_str());
    runs.push_back({imgN, truth, ours, sift});
  }
  std::printf(
      "%s pairs meeting all targets: %d / %d; total CPU time facet %.0f ms, SIFT %.0f ms "
      "(ratio %.2f)\n",
      name.c_str(), met, last - 1, oursMs, siftMs, siftMs > 0 ? oursMs / siftMs : 0.0);
  if (withDenseReference) {
    std::printf(
        "\n%s against a dense reference (OpenCV ECC homography from the published H, every pixel "
        "of the overlap;\n   corr = its correlation; corner errors as above):\n",
        name.c_str());
    std::printf("%-5s | %9s %6s | %8s %8s | %s\n", "pair", "published", "corr", "facet", "SIFT",
                "facet <= SIFT");
    int closer = 0, solved = 0;
    for (int n = 2; n <= last; ++n) {
      const auto& [imgN, published, ours, sift] = runs[n - 2];
      const std::optional<DenseReference> dense = denseReference(img1, imgN, published);
      if (!dense) {
        std::printf("1-%d   | ECC did not converge\n", n);
        continue;
      }
      const double f = ours.ok ? cornerError(ours.H, dense->H, img1.size()) : -1;
      const double g = sift.ok ? cornerError(sift.H, dense->H, img1.size()) : -1;
      const bool siftSolves = sift.ok && g <= 3.0;
      const bool better = ours.ok && f <= 3.0 && (!siftSolves || f <= g);
      solved += siftSolves;
      closer += siftSolves && better;
      std::printf("1-%d   | %9.2f %6.3f | %8.2f %8.2f | %s\n", n,
                  cornerError(published, dense->H, img1.size()), dense->correlation, f, g,
                  better ? "yes" : "no");
    }
    std::printf(
        "%s: facet within 3 px of the dense reference and at most SIFT's error on %d of "
        "the %d pairs SIFT solves\n",
        name.c_str(), closer, solved);
  }
  if (!withGlobalStage) return;
  // Transparency: what the global log-polar matching finds on its own, before the
  // warp-and-rematch refinement produces the final matches above.
  std::printf("\nfacet global stage alone (log-polar NCC + robust fit, refineIterations = 0):\n");
  std::printf("%-5s | %7s %7s %7s %10s\n", "pair", "matches", "correct", "inliers", "corner");
  for (int n = 2; n <= last; ++n) {
    const cv::Mat imgN = readGrey(dir + "/img" + std::to_string(n) + ".png");
    const cv::Matx33d truth = readHomography(dir + "/H1to" + std::to_string(n) + "p");
    facet::RegistrationParams p = grafParams();
    p.refineIterations = 0;
    const Outcome g = runOurs(img1, imgN, truth, p);
    if (g.ok)
      std::printf("1-%d   | %7d %7d %7d %10.2f\n", n, g.matches, g.correct, g.inliers,
                  g.cornerError);
    else
      std::printf("1-%d   | %7d %7d       - no transform: %s\n", n, g.matches, g.correct,
                  g.failure.c_str());
  }
}

void syntheticTable(const std::string& dir, int count) {
  const cv::Mat img1 = readGrey(dir + "/img1.png");
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> angle(-180, 180), logScale(std::log(0.33), std::log(3.0));
  std::uniform_int_distribution<int> ox(0, img1.cols - 256), oy(0, img1.rows - 256);
  int success = 0;
  double totalMs = 0, worst = 0;
  for (int k = 0; k < count; ++k) {
    const double a = angle(rng) * CV_PI / 180, s = std::exp(logScale(rng));
    const cv::Point2d origin(ox(rng), oy(rng));
    const cv::Mat ref = img1(cv::Rect(int(origin.x), int(origin.y), 256, 256)).clone();
    // truth: q = c_img + s R(a) (p - c_ref), R(a) = [[cos, sin], [-sin, cos]]
    const cv::Point2d cr(127.5, 127.5), ci(159.5, 159.5);
    const double c = std::cos(a) * s, sn = std::sin(a) * s;
    const cv::Matx33d truth(c, sn, ci.x - c * cr.x - sn * cr.y, -sn, c, ci.y + sn * cr.x - c * cr.y,
                            0, 0, 1);
    // image pixel q shows img1 at origin + truth^-1 q
    const cv::Matx33d shift(1, 0, -origin.x, 0, 1, -origin.y, 0, 0, 1);
    const cv::Matx33d full = truth * shift;
    // A camera integrates over its pixels: when the view shrinks, low-pass first (no aliasing).
    cv::Mat source;
    if (s < 1) {
      const double sigma = 0.5 * std::sqrt(1.0 / (s * s) - 1.0);
      cv::GaussianBlur(img1, source, cv::Size(), sigma, sigma);
    } else {
      source = img1;
    }
    cv::Mat image;
    cv::warpAffine(source, image,
                   cv::Mat(cv::Matx23d(full(0, 0), full(0, 1), full(0, 2), full(1, 0), full(1, 1),
                                       full(1, 2))),
                   cv::Size(320, 320), cv::INTER_LINEAR, cv::BORDER_CONSTANT, cv::Scalar(0));
    const cv::Mat noise = pairNoise(image.size(), 3, 1000 + static_cast<std::uint64_t>(k));
    cv::Mat noisy;
    image.convertTo(noisy, CV_16S);
    noisy += noise;
    noisy.convertTo(image, CV_8U);
    facet::RegistrationParams p;
    p.model = facet::TransformModel::Similarity;
    const CpuTime t0 = cpuNow();
    const facet::RegistrationResult r = facet::registerImages(ref, image, p);
    const double ms = msSince(t0);
    totalMs += ms;
    const double err = r.status.ok() ? cornerError(r.H, truth, ref.size()) : 1e9;
    worst = std::max(worst, std::min(err, 1e9));
    if (err <= 2.0)
      ++success;
    else
      std::printf("  synthetic %d failed: angle %.1f deg scale %.2f -> %s %s corner error %.2f\n",
                  k, a * 180 / CV_PI, s,
                  r.status.ok() ? "ok" : std::string(facet::toString(r.status.cause)).c_str(),
                  r.status.message.c_str(), err);
  }
  std::printf(
      "\n== Synthetic similarity pairs (graf img1 crops 256x256 -> 320x320, any angle, scale "
      "0.33-3, noise sigma 3) ==\n");
  std::printf(
      "pairs %d  success (corner error <= 2 px) %d = %.1f%% (target >= 95%%)  mean CPU time %.1f "
      "ms\n",
      count, success, 100.0 * success / count, totalMs / count);
}

// Real photographs from Debian's opencv-doc package (examples/data), warped by known
// homographies: SYNTHETIC warps (pre-blurred where the view shrinks, noise sigma 2), not real
// viewpoint changes. The defaults were set on graf; the first set's zoom rows then led to the
// re-matching grid's density rule. The held-out set was run once after that change, and
// nothing has been chosen on it: keep it so. The zoom-3 warp came later, with the joint vote on
// rotation and scale (rotation_scale_vote.hpp), designed on photographs of the first set
// magnified 2.5-4 times; its held-out rows were first run with that change in place. The second
// tuned set (other photographs and drawings of the same package, fourteen chosen at once) showed
// the pairs where a repeated pattern hides the true partners (look-alike windows, the
// lookalikeCandidates stage); the second held-out set was listed before any of its rows was run,
// and first run with that stage and without it.
void photoWarpTable(const char* title, const std::vector<std::string>& photos) {
  const std::string dir = "/usr/share/doc/opencv-doc/examples/data";
  struct Warp {
    const char* name;
    double deg, scale, tilt, px;  // rotation, zoom, foreshortening along x, perspective term
  };
  const std::vector<Warp> warps = {{"rot30 zoom0.8 persp", 30, 0.8, 1.0, 2e-4},
                                   {"tilt 0.6 rot10 persp", 10, 1.0, 0.6, 4e-4},
                                   {"zoom1.6 rot70", 70, 1.6, 1.0, 0.0},
                                   {"zoom3 rot-50", -50, 3.0, 1.0, 0.0}};
  std::printf(
      "\n== %s: photographs of Debian's opencv-doc (examples/data) under SYNTHETIC "
      "homographies (noise sigma 2); defaults ==\n",
      title);
  std::printf("%-20s %-21s | %7s %7s %8s %6s %8s %-18s | %7s %7s %8s %8s | %s\n", "photo", "warp",
              "correct", "inliers", "corner", "unc", "ms", "stage", "correct", "inliers", "corner",
              "ms", "targets");
  int pairs = 0, met = 0;
  double oursMs = 0, siftMs = 0;
  for (const std::string& name : photos) {
    cv::Mat photo = readGrey(dir + "/" + name);
    if (photo.empty()) {
      std::printf("%-20s cannot read %s/%s (apt-get install opencv-doc): skipped\n", name.c_str(),
                  dir.c_str(), name.c_str());
      continue;
    }
    if (photo.cols > 640)
      cv::resize(photo, photo, cv::Size(), 640.0 / photo.cols, 640.0 / photo.cols, cv::INTER_AREA);
    const cv::Point2d c((photo.cols - 1) / 2.0, (photo.rows - 1) / 2.0);
    std::uint64_t warpIndex = 0;
    for (const Warp& w : warps) {
      const double a = w.deg * CV_PI / 180;
      const cv::Matx33d toOrigin(1, 0, -c.x, 0, 1, -c.y, 0, 0, 1),
          back(1, 0, c.x, 0, 1, c.y, 0, 0, 1);
      const cv::Matx33d rot(std::cos(a) * w.scale, std::sin(a) * w.scale, 0, -std::sin(a) * w.scale,
                            std::cos(a) * w.scale, 0, 0, 0, 1);
      const cv::Matx33d view(w.tilt, 0, 0, 0, 1, 0, w.px, 0, 1);
      cv::Matx33d truth = back * view * rot * toOrigin;
      truth *= 1.0 / truth(2, 2);
      const double shrink = std::min(w.scale * w.tilt, 1.0);
      // A new image for the low-passed copy: a header sharing the photograph's pixels would be
      // blurred in place, the reference with it, and every later warp's too.
      cv::Mat source;
      if (shrink < 1) {
        const double sigma = 0.5 * std::sqrt(1.0 / (shrink * shrink) - 1.0);
        cv::GaussianBlur(photo, source, cv::Size(), sigma, sigma);
      } else {
        source = photo;
      }
      cv::Mat image;
      cv::warpPerspective(source, image, cv::Mat(truth), photo.size(), cv::INTER_LINEAR,
                          cv::BORDER_CONSTANT, cv::Scalar(0));
      const cv::Mat noise = pairNoise(image.size(), 2, pairSeed(name, warpIndex++));
      cv::Mat noisy;
      image.convertTo(noisy, CV_16S);
      noisy += noise;
      noisy.convertTo(image, CV_8U);
      const Outcome ours = runOurs(photo, image, truth, grafParams());
      const Outcome sift = runSift(photo, image, truth);
      const bool siftSolves = sift.ok && sift.cornerError <= 3.0;
      const bool good = ours.ok && ours.cornerError <= 3.0 &&
                        (!siftSolves || ours.cornerError <= sift.cornerError) &&
                        ours.correct > sift.correct;
      ++pairs;
      met += good;
      oursMs += ours.ms;
      siftMs += sift.ms;
      std::printf("%-20s %-21s | %7d %7d %8.2f %6.3f %8.1f %-18s | %7d %7d %8.2f %8.1f | %s\n",
                  name.c_str(), w.name, ours.correct, ours.inliers, ours.ok ? ours.cornerError : -1,
                  ours.ok ? ours.uncertainty : -1, ours.ms, ours.stage.c_str(), sift.correct,
                  sift.inliers, sift.ok ? sift.cornerError : -1, sift.ms, good ? "met" : "MISSED");
      if (!ours.ok) std::printf("  facet found no transform: %s\n", ours.failure.c_str());
    }
  }
  std::printf(
      "pairs meeting the accuracy and match targets: %d / %d; total CPU time facet %.0f ms, SIFT "
      "%.0f ms (ratio %.2f, target <= 1)\n",
      met, pairs, oursMs, siftMs, siftMs > 0 ? oursMs / siftMs : 0.0);
}

void nccTable(const std::string& dir, bool smoke) {
  const cv::Mat a8 = readGrey(dir + "/img1.png");
  const cv::Mat b8 = readGrey(dir + "/img2.png");
  cv::Mat a, b;
  a8.convertTo(a, CV_32F, 1 / 255.0);
  b8.convertTo(b, CV_32F, 1 / 255.0);
  facet::HarrisParams hp;
  hp.maxCorners = smoke ? 120 : 400;
  facet::LogPolarParams lp;
  auto windows = [&](const cv::Mat& g) {
    const auto pyr = facet::buildSamplingPyramid(g);
    std::vector<facet::LogPolarWindow> w;
    for (const auto& c : facet::detectHarrisCorners(g, hp)) {
      auto x = facet::sampleLogPolar(pyr, c.pt, cv::Matx22d(c.scale, 0, 0, c.scale), lp);
      if (x.valid) w.push_back(std::move(x));
    }
    return w;
  };
  const auto wa = windows(a), wb = windows(b);
  std::printf(
      "\n== NCC accelerations: all-pairs matching of %zu x %zu log-polar windows (graf 1-2) ==\n",
      wa.size(), wb.size());
  std::printf("%-26s %10s %9s %8s %s\n", "variant", "CPU ms", "speed-up", "matches",
              "identical to plain");
  struct Variant {
    const char* name;
    facet::NccAccelerations acc;
  };
  const Variant variants[] = {{"plain NCC", {false, false, false}},
                              {"1D projections", {true, false, false}},
                              {"sum tables", {false, true, false}},
                              {"Jensen early termination", {false, false, true}},
                              {"all three", {true, true, true}}};
  std::vector<facet::WindowMatch> plain;
  double plainMs = 0;
  for (const auto& v : variants) {
    facet::NccMatchParams mp;
    mp.accelerations = v.acc;
    const CpuTime t0 = cpuNow();
    const auto m = facet::matchWindows(wa, wb, lp.ringShifts, mp);
    const double ms = msSince(t0);
    bool same = true;
    if (plain.empty() && !v.acc.projections && !v.acc.sumTables && !v.acc.jensen) {
      plain = m;
      plainMs = ms;
    } else {
      same = m.size() == plain.size();
      for (std::size_t i = 0; same && i < m.size(); ++i)
        same = m[i].ref == plain[i].ref && m[i].image == plain[i].image &&
               m[i].best.score == plain[i].best.score &&
               m[i].best.ringShift == plain[i].best.ringShift &&
               m[i].best.angleShift == plain[i].best.angleShift;
    }
    std::printf("%-26s %10.1f %9.2f %8zu %s\n", v.name, ms, plainMs / ms, m.size(),
                same ? "yes" : "NO");
  }
}

// Views out of focus: Oxford second and third images blurred by a disk (the geometric blur of a
// defocused lens, radius 2, 4 and 6 px), against the published H (a blur moves no point). facet's
// re-matching brings the views to one focus by a Gaussian (relative_defocus.hpp), a model of the
// disk and not the disk itself; the same registration without it (matchDefocus off) and SIFT
// run beside it.
void defocusTable() {
  std::printf(
      "\n== Defocused views: Oxford img1 -> imgN blurred by a disk of radius r px (corner error "
      "against the published H) ==\n"
      "pair          r | correct inliers   corner | without the focus matching: correct inliers "
      "  corner | SIFT: correct inliers   corner\n");
  int better = 0, rows = 0;
  for (const char* name : {"graf", "leuven", "boat"})
    for (int n : {2, 3})
      for (int radius : {2, 4, 6}) {
        const std::string dir = std::string(FACET_TEST_DATA_DIR) + "/oxford-" + name;
        const cv::Mat a = readGrey(dir + "/img1.png");
        const cv::Mat sharp = readGrey(dir + "/img" + std::to_string(n) + ".png");
        const cv::Matx33d truth = readHomography(dir + "/H1to" + std::to_string(n) + "p");
        cv::Mat disk = cv::Mat::zeros(2 * radius + 1, 2 * radius + 1, CV_32F);
        cv::circle(disk, {radius, radius}, radius, cv::Scalar(1), cv::FILLED, cv::LINE_AA);
        disk /= cv::sum(disk)[0];
        cv::Mat b;
        cv::filter2D(sharp, b, -1, disk, {-1, -1}, 0, cv::BORDER_REFLECT);
        facet::RegistrationParams off = grafParams();
        off.matchDefocus = false;
        const Outcome on = runOurs(a, b, truth, grafParams());
        const Outcome without = runOurs(a, b, truth, off);
        const Outcome sift = runSift(a, b, truth);
        std::printf("%-7s 1-%d %2d | %7d %7d %8.2f | %35d %7d %8.2f | %13d %7d %8.2f\n", name, n,
                    radius, on.correct, on.inliers, on.cornerError, without.correct,
                    without.inliers, without.cornerError, sift.correct, sift.inliers,
                    sift.cornerError);
        ++rows;
        if (on.cornerError <= without.cornerError) ++better;
      }
  std::printf(
      "pairs where the focus matching's corner error is at most the one without it: %d / %d\n",
      better, rows);
}

// Other Oxford sequences in the repository (tests/data/oxford-<name>, with their READMEs).
// The dense reference where its model holds: no change of light, one scale across the image.
struct Sequence {
  const char* name;
  const char* change;
  bool denseReference;
};
const Sequence kOtherSequences[] = {
    {"boat", "zoom and rotation", true}, {"bikes", "blur", true}, {"leuven", "light", false}};

// The Oxford graf sequence in the repository (tests/data/oxford-graf, with its README).
std::string defaultDataDir() {
  return std::string(FACET_TEST_DATA_DIR) + "/oxford-graf";
}

}  // namespace

int main(int argc, char** argv) {
  bool smoke = false;
  std::string dir = defaultDataDir();
  int synthetic = 100;
  std::vector<std::string> photos;
  for (int i = 1; i < argc; ++i) {
    const std::string arg = argv[i];
    if (arg == "--smoke")
      smoke = true;
    else if (arg == "--data" && i + 1 < argc)
      dir = argv[++i];
    else if (arg == "--synthetic" && i + 1 < argc)
      synthetic = std::stoi(argv[++i]);
    else if (arg == "--photos" && i + 1 < argc) {
      std::stringstream list(argv[++i]);
      for (std::string name; std::getline(list, name, ',');)
        if (!name.empty()) photos.push_back(name);
    } else {
      std::fprintf(stderr,
                   "usage: bench_registration [--smoke] [--data DIR] [--synthetic N] "
                   "[--photos A.jpg,B.png,...]\n");
      return 1;
    }
  }
  cv::setNumThreads(1);  // single-threaded, like facet's algorithms
  if (!photos.empty()) {
    photoWarpTable("Chosen set", photos);
    return 0;
  }
  if (smoke) synthetic = std::min(synthetic, 6);
  sequenceTable(dir, "graf", "viewpoint", smoke, smoke ? 1 : 3, true, false);
  if (!smoke)
    for (const auto& [name, change, dense] : kOtherSequences)
      sequenceTable(std::string(FACET_TEST_DATA_DIR) + "/oxford-" + name, name, change, false, 3,
                    false, dense);
  syntheticTable(dir, synthetic);
  if (!smoke) defocusTable();
  if (smoke) {
    photoWarpTable("Smoke", {"fruits.jpg"});
  } else {
    photoWarpTable("Tuned set", {"fruits.jpg", "baboon.jpg", "aero1.jpg", "leuvenA.jpg",
                                 "building.jpg", "home.jpg", "butterfly.jpg", "messi5.jpg"});
    photoWarpTable("Held-out set",
                   {"apple.jpg", "orange.jpg", "HappyFish.jpg", "blox.jpg", "box_in_scene.png",
                    "starry_night.jpg", "stuff.jpg", "smarties.png", "Blender_Suzanne1.jpg",
                    "squirrel_cls.jpg", "sudoku.png", "graf3.png"});
    photoWarpTable(
        "Second tuned set",
        {"pic1.png", "pic3.png", "pic5.png", "cards.png", "chicky_512.png", "ela_original.jpg",
         "aloeL.jpg", "basketball1.png", "board.jpg", "licenseplate_motion.jpg", "left01.jpg",
         "right.jpg", "detect_blob.png", "LinuxLogo.jpg"});
    photoWarpTable(
        "Second held-out set",
        {"pic2.png", "pic4.png", "pic6.png", "ellipses.jpg", "opencv-logo.png", "WindowsLogo.jpg",
         "chessboard.png", "box.png", "notes.png", "imageTextN.png", "rubberwhale1.png", "ml.png"});
  }
  nccTable(dir, smoke);
  return 0;
}
