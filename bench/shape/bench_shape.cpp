// bench_shape: shape-based matching (findShapeModel with least-squares refinement) on generated
// scenes of the bracket part, beside OpenCV baselines on the same scenes: rotated
// cv::matchTemplate (NCC, 1-degree steps, parabolic subpixel peak) and cv::GeneralizedHoughGuil.
//
//   bench_shape [--smoke] [--scenes N] [--verbose] [--blur-model pixel-grid|lens]
//   (--verbose lists missed scenes; --blur-model: where the Gaussian of scenes and template acts,
//   on the sampled image (default) or before pixel integration as a lens does; lens is slower)
//
// Prints one table; timings are medians per image, on this machine, in the same run.

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <ctime>
#include <numeric>
#include <optional>
#include <random>
#include <string>
#include <vector>

#include <opencv2/imgproc.hpp>

#include "algorithms/shape/find_shape_model.hpp"
#include "algorithms/shape/shape_model.hpp"
#include "tests/support/scene/parts.hpp"

namespace {

using namespace facet;
using Clock = std::chrono::steady_clock;

constexpr double kPartGrey = 170.0;
constexpr double kBackground = 50.0;  // contrast 120

// CPU time of the whole process (all threads), ms: robust against other jobs on a shared machine,
// and an upper bound of the wall time on an idle one.
double cpuMs() {
  timespec t{};
  clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &t);
  return t.tv_sec * 1e3 + t.tv_nsec / 1e6;
}

double loadAverage() {
  double load[1] = {0.0};
  return getloadavg(load, 1) == 1 ? load[0] : NAN;
}

double msSince(Clock::time_point t0) {
  return std::chrono::duration<double, std::milli>(Clock::now() - t0).count();
}

double median(std::vector<double> v) {
  if (v.empty()) return NAN;
  std::nth_element(v.begin(), v.begin() + v.size() / 2, v.end());
  return v[v.size() / 2];
}

double rms(const std::vector<double>& v) {
  if (v.empty()) return NAN;
  double s = 0;
  for (double x : v) s += x * x;
  return std::sqrt(s / v.size());
}

double maxAbs(const std::vector<double>& v) {
  double m = 0;
  for (double x : v) m = std::max(m, std::abs(x));
  return v.empty() ? NAN : m;
}

// Where the scenes' (and the template's) blur acts: --blur-model pixel-grid|lens.
scene::BlurModel gBlurModel = scene::BlurModel::PixelGrid;

scene::SceneSpec specFor(cv::Size size, std::uint64_t seed) {
  scene::SceneSpec spec;
  spec.size = size;
  spec.background = kBackground;
  spec.blurSigma = 0.8;
  spec.blurModel = gBlurModel;
  spec.noiseSigma = 2.0;
  spec.seed = seed;
  return spec;
}

struct TestScene {
  cv::Mat image;
  std::vector<Pose2D> truth;  // empty for clutter-only scenes
};

// One part at a random pose (any angle), clutter around it, optional occlusion.
TestScene randomScene(cv::Size size, std::uint64_t seed, double scaleLo, double scaleHi,
                      double occlusion, bool withPart = true) {
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  const scene::PartDrawing part = scene::bracketPart();
  scene::Scene s(specFor(size, seed));
  TestScene out;
  std::vector<cv::Rect2d> keepOut;
  if (withPart) {
    const double scale = scaleLo + (scaleHi - scaleLo) * u(rng);
    const double margin = 95.0 * scale;
    Pose2D pose{margin + u(rng) * (size.width - 2 * margin),
                margin + u(rng) * (size.height - 2 * margin), (2 * u(rng) - 1) * std::numbers::pi,
                scale};
    const cv::Rect2d box = scene::placePart(s, part, pose, kPartGrey, kBackground);
    keepOut.push_back(box);
    if (occlusion > 0) s.addOccluder(box, occlusion, 110.0);
    out.truth.push_back(pose);
  }
  const int clutter = size.area() / 20000;
  s.addClutter(clutter, 10, 60, keepOut, 0, 255);
  out.image = s.render();
  return out;
}

// 20 instances on a 5 x 4 grid of cells in a 1280 x 1024 image.
TestScene crowdScene(std::uint64_t seed) {
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  const scene::PartDrawing part = scene::bracketPart();
  scene::Scene s(specFor({1280, 1024}, seed));
  TestScene out;
  for (int row = 0; row < 4; ++row)
    for (int col = 0; col < 5; ++col) {
      Pose2D pose{128.0 + 256 * col + 20 * (2 * u(rng) - 1),
                  128.0 + 256 * row + 20 * (2 * u(rng) - 1), (2 * u(rng) - 1) * std::numbers::pi,
                  1.0};
      scene::placePart(s, part, pose, kPartGrey, kBackground);
      out.truth.push_back(pose);
    }
  out.image = s.render();
  return out;
}

struct Errors {
  std::vector<double> position, angleDeg, scaleRel, ms, cpu;
  int found = 0, scenes = 0, wrong = 0;
  // Misses whose true pose itself scores below the minimum: the occluder hid more than that share
  // of the model's edges, and a score that means "share of the model seen" must not find them.
  int hiddenBeyondMinimum = 0;
};

// The match nearest to the truth counts as found when within 2 px and 1 degree.
bool score(const Pose2D& truth, const std::vector<ShapeMatch>& matches, Errors& e) {
  for (const auto& m : matches) {
    const double dp = std::hypot(m.x - truth.x, m.y - truth.y);
    const double da = degrees(wrapAngle(m.angle - truth.angle));
    if (dp < 2.0 && std::abs(da) < 1.0) {
      e.position.push_back(dp);
      e.angleDeg.push_back(da);
      e.scaleRel.push_back(m.scale / truth.scale - 1.0);
      ++e.found;
      return true;
    }
  }
  return false;
}

// --- OpenCV baselines ------------------------------------------------------------------------

struct Baseline {
  std::vector<double> position, angleDeg, ms, cpu;
  int found = 0, scenes = 0;
};

// Rotated templates for NCC: the template padded with background to hold any rotation.
// The template is placed so that its reference point ((w-1)/2, (h-1)/2) is the canvas centre.
std::vector<cv::Mat> rotatedTemplates(const cv::Mat& templ, int stepDeg) {
  int side = static_cast<int>(std::ceil(std::hypot(templ.cols, templ.rows)));
  if ((side - templ.cols) % 2) ++side;
  cv::Mat canvas(side, side, templ.type(), cv::Scalar(kBackground));
  const int ox = (side - templ.cols) / 2;
  const int oy = ox + (templ.cols - templ.rows) / 2;  // the bracket template has w - h even
  templ.copyTo(canvas(cv::Rect(ox, oy, templ.cols, templ.rows)));
  std::vector<cv::Mat> out;
  for (int deg = 0; deg < 360; deg += stepDeg) {
    // cv::getRotationMatrix2D turns counter-clockwise on screen for positive angles, as we do.
    const cv::Mat r =
        cv::getRotationMatrix2D(cv::Point2f((side - 1) / 2.0f, (side - 1) / 2.0f), deg, 1.0);
    cv::Mat rotated;
    cv::warpAffine(canvas, rotated, r, canvas.size(), cv::INTER_LINEAR, cv::BORDER_CONSTANT,
                   cv::Scalar(kBackground));
    out.push_back(rotated);
  }
  return out;
}

double parabola(double m, double z, double p) {
  const double d = m - 2 * z + p;
  return d < 0 ? std::clamp(0.5 * (m - p) / d, -0.5, 0.5) : 0.0;
}

void runNcc(const std::vector<cv::Mat>& templates, int stepDeg, const TestScene& sc, Baseline& b) {
  const double c0 = cpuMs();
  const auto t0 = Clock::now();
  double bestScore = -2;
  int bestDeg = 0;
  cv::Point bestLoc;
  std::vector<cv::Mat> results(templates.size());
  for (int deg = 0; deg < static_cast<int>(templates.size()); ++deg) {
    cv::matchTemplate(sc.image, templates[deg], results[deg], cv::TM_CCOEFF_NORMED);
    double mx;
    cv::Point loc;
    cv::minMaxLoc(results[deg], nullptr, &mx, nullptr, &loc);
    if (mx > bestScore) bestScore = mx, bestDeg = deg, bestLoc = loc;
  }
  const cv::Mat& r = results[bestDeg];
  auto at = [&](int dx, int dy) {
    const cv::Point q = bestLoc + cv::Point(dx, dy);
    return cv::Rect(0, 0, r.cols, r.rows).contains(q) ? double(r.at<float>(q)) : -1.0;
  };
  const double z = at(0, 0);
  const double sx = parabola(at(-1, 0), z, at(1, 0)), sy = parabola(at(0, -1), z, at(0, 1));
  const int n = static_cast<int>(templates.size());
  const double am = results[(bestDeg + n - 1) % n].at<float>(bestLoc);
  const double ap = results[(bestDeg + 1) % n].at<float>(bestLoc);
  const double angle = (bestDeg + parabola(am, z, ap)) * stepDeg;
  const double half = (templates[0].cols - 1) / 2.0;
  const double x = bestLoc.x + sx + half, y = bestLoc.y + sy + half;
  b.ms.push_back(msSince(t0));
  b.cpu.push_back(cpuMs() - c0);
  ++b.scenes;
  const Pose2D& truth = sc.truth.front();
  const double dp = std::hypot(x - truth.x, y - truth.y);
  const double da = degrees(wrapAngle(radians(angle) - truth.angle));
  if (dp < 2.0 && std::abs(da) < 1.5) {
    ++b.found;
    b.position.push_back(dp);
    b.angleDeg.push_back(da);
  }
}

void runGuil(cv::Ptr<cv::GeneralizedHoughGuil>& guil, const TestScene& sc, Baseline& b) {
  const double c0 = cpuMs();
  const auto t0 = Clock::now();
  std::vector<cv::Vec4f> found;
  std::vector<cv::Vec3i> votes;
  guil->detect(sc.image, found, votes);
  b.ms.push_back(msSince(t0));
  b.cpu.push_back(cpuMs() - c0);
  ++b.scenes;
  if (found.empty()) return;
  std::size_t best = 0;
  for (std::size_t i = 1; i < found.size(); ++i)
    if (votes[i][0] + votes[i][2] > votes[best][0] + votes[best][2]) best = i;
  const Pose2D& truth = sc.truth.front();
  // Guil reports the template centre and a clockwise angle in degrees.
  const double dp = std::hypot(found[best][0] - truth.x, found[best][1] - truth.y);
  const double da = degrees(wrapAngle(radians(-found[best][3]) - truth.angle));
  if (dp < 2.0 && std::abs(da) < 1.5) {
    ++b.found;
    b.position.push_back(dp);
    b.angleDeg.push_back(da);
  }
}

void printRow(const char* name, const Errors& e, const char* target) {
  std::printf(
      "| %-34s | %4d | %5.1f%% | %7.4f | %7.4f | %7.4f | %7.4f | %8.2e | %7.2f | %7.2f | %s |\n",
      name, e.scenes, 100.0 * e.found / std::max(1, e.scenes), rms(e.position), maxAbs(e.position),
      rms(e.angleDeg), maxAbs(e.angleDeg), rms(e.scaleRel), median(e.ms), median(e.cpu), target);
}

void printBaseline(const char* name, const Baseline& b, const Errors& ours) {
  std::printf(
      "| %-34s | %4d | %5.1f%% | %7.4f | %7.4f | %7.4f | %7.4f | %8s | %7.1f | %7.1f | CPU time "
      "x%.0f of ours, pos RMS x%.0f, angle RMS x%.1f |\n",
      name, b.scenes, 100.0 * b.found / std::max(1, b.scenes), rms(b.position), maxAbs(b.position),
      rms(b.angleDeg), maxAbs(b.angleDeg), "-", median(b.ms), median(b.cpu),
      median(b.cpu) / median(ours.cpu), rms(b.position) / rms(ours.position),
      rms(b.angleDeg) / rms(ours.angleDeg));
}

}  // namespace

int main(int argc, char** argv) {
  bool smoke = false, verbose = false;
  int scenes = 50, baselineScenes = 10;
  for (int i = 1; i < argc; ++i) {
    if (!std::strcmp(argv[i], "--smoke")) smoke = true;
    if (!std::strcmp(argv[i], "--verbose")) verbose = true;
    if (!std::strcmp(argv[i], "--scenes") && i + 1 < argc) scenes = std::atoi(argv[++i]);
    if (!std::strcmp(argv[i], "--blur-model") && i + 1 < argc) {
      const std::string m = argv[++i];
      if (m != "lens" && m != "pixel-grid") {
        std::fprintf(stderr, "bench_shape: --blur-model must be lens or pixel-grid\n");
        return 2;
      }
      gBlurModel = m == "lens" ? scene::BlurModel::Lens : scene::BlurModel::PixelGrid;
    }
  }
  if (smoke) scenes = 4, baselineScenes = 1;
  const int clutterScenes = smoke ? 4 : 100;
  const int crowdScenes = smoke ? 1 : 5;

  // The model: the bracket's template, rendered like the scenes.
  const scene::PartDrawing part = scene::bracketPart();
  const cv::Mat templ = scene::templateScene(part, specFor({}, 999), kPartGrey).render();
  ShapeModel model = createShapeModel(templ);
  ShapeModelParams scaled;
  scaled.scaleMin = 0.8;
  scaled.scaleMax = 1.2;
  ShapeModel scaleModel = createShapeModel(templ, scaled);
  std::printf(
      "bench_shape%s: scenes blurred by the %s model; model %zu points on level 0, %d levels, "
      "%zu subpixel points, edges by %s\n",
      smoke ? " --smoke" : "", scene::blurModelName(gBlurModel), model.levels[0].points.size(),
      model.numLevels(), model.finePoints.size(), edgeEstimatorName(model.edgeEstimator));
  for (const EdgeEstimatorTrial& t : model.edgeEstimatorTrials)
    std::printf("  training test, %s: turned copies found %.4f px from their poses\n",
                edgeEstimatorName(t.estimator), t.poseError);

  FindParams find;  // full circle, least squares, min score 0.7, one match
  find.numMatches = 1;

  Errors vga, sxga, scale, occluded, occludedHeldOut, clutter, crowd;
  std::vector<TestScene> vgaScenes;
  for (int i = 0; i < scenes; ++i) {
    auto run = [&](const TestScene& sc, const ShapeModel& m, const FindParams& p, Errors& e) {
      const double c0 = cpuMs();
      const auto t0 = Clock::now();
      const auto matches = findShapeModel(sc.image, m, p);
      e.ms.push_back(msSince(t0));
      e.cpu.push_back(cpuMs() - c0);
      ++e.scenes;
      if (!score(sc.truth.front(), matches, e)) {
        ++e.wrong;
        // The score at the true pose: a search in its neighbourhood without a minimum.
        FindParams near = p;
        near.minScore = 0.05;
        near.angleStart = sc.truth.front().angle - radians(1.0);
        near.angleExtent = radians(2.0);
        for (const auto& m : findShapeModel(sc.image, m, near))
          if (std::hypot(m.x - sc.truth.front().x, m.y - sc.truth.front().y) < 1.0 &&
              m.score < p.minScore)
            ++e.hiddenBeyondMinimum;
        if (verbose) {
          const Pose2D& t = sc.truth.front();
          std::printf("missed: truth %.2f %.2f %.2f deg scale %.3f;", t.x, t.y, degrees(t.angle),
                      t.scale);
          for (const auto& m : matches)
            std::printf(" match %.2f %.2f %.2f deg scale %.3f score %.3f;", m.x, m.y,
                        degrees(m.angle), m.scale, m.score);
          std::printf("\n");
        }
      }
    };
    vgaScenes.push_back(randomScene({640, 480}, 1000 + i, 1.0, 1.0, 0.0));
    run(vgaScenes.back(), model, find, vga);
    run(randomScene({1280, 1024}, 2000 + i, 1.0, 1.0, 0.0), model, find, sxga);
    run(randomScene({640, 480}, 3000 + i, 0.8, 1.2, 0.0), scaleModel, find, scale);
    FindParams low = find;
    low.minScore = 0.5;
    run(randomScene({640, 480}, 4000 + i, 1.0, 1.0, 0.4), model, low, occluded);
    // The same kind of scene from seeds no change was ever tried on: the row above has been
    // looked at miss by miss, this one only counted.
    run(randomScene({640, 480}, 7000 + i, 1.0, 1.0, 0.4), model, low, occludedHeldOut);
  }
  for (int i = 0; i < clutterScenes; ++i) {
    const TestScene sc = randomScene({640, 480}, 5000 + i, 1, 1, 0, false);
    FindParams all = find;
    all.numMatches = 0;
    const double c0 = cpuMs();
    const auto t0 = Clock::now();
    const auto matches = findShapeModel(sc.image, model, all);
    clutter.ms.push_back(msSince(t0));
    clutter.cpu.push_back(cpuMs() - c0);
    ++clutter.scenes;
    if (matches.empty()) ++clutter.found;  // "found" = correctly nothing
  }
  for (int i = 0; i < crowdScenes; ++i) {
    const TestScene sc = crowdScene(6000 + i);
    FindParams all = find;
    all.numMatches = 0;
    const double c0 = cpuMs();
    const auto t0 = Clock::now();
    const auto matches = findShapeModel(sc.image, model, all);
    crowd.ms.push_back(msSince(t0));
    crowd.cpu.push_back(cpuMs() - c0);
    ++crowd.scenes;
    int hits = 0;
    for (const auto& t : sc.truth) {
      int n = 0;
      for (const auto& m : matches)
        n += std::hypot(m.x - t.x, m.y - t.y) < 2.0 &&
             std::abs(degrees(wrapAngle(m.angle - t.angle))) < 1.0;
      hits += n == 1;
    }
    if (hits == 20 && matches.size() == 20) ++crowd.found;
  }

  Baseline ncc, guil;
  {
    // 1-degree steps; the smoke run (a CI check, not a measurement) uses 10-degree steps.
    const int nccStep = smoke ? 10 : 1;
    const auto templates = rotatedTemplates(templ, nccStep);
    for (int i = 0; i < baselineScenes && i < static_cast<int>(vgaScenes.size()); ++i)
      runNcc(templates, nccStep, vgaScenes[i], ncc);
    auto g = cv::createGeneralizedHoughGuil();
    g->setMinAngle(0);
    g->setMaxAngle(360);
    g->setAngleStep(1);
    g->setMinScale(0.95);  // Guil needs a scale interval; one step of 0.05 around 1
    g->setMaxScale(1.05);
    g->setScaleStep(0.05);
    g->setCannyLowThresh(30);
    g->setCannyHighThresh(90);
    g->setTemplate(templ);
    for (int i = 0; i < baselineScenes && i < static_cast<int>(vgaScenes.size()); ++i)
      runGuil(g, vgaScenes[i], guil);
  }

  std::printf(
      "\n| case | scenes | found | pos RMS px | pos max px | angle RMS deg | angle max deg | scale "
      "rel RMS | median ms wall | median ms CPU | target |\n");
  std::printf("|---|---|---|---|---|---|---|---|---|---|---|\n");
  printRow("640x480, 360 deg", vga, "<= 8 ms, 0.02 px (max 0.06), 0.01 deg (max 0.03)");
  printRow("1280x1024, 360 deg", sxga, "<= 25 ms, same accuracy");
  printRow("640x480, scale 0.8-1.2", scale, "<= 4x fixed-scale time, scale RMS <= 5e-4");
  printRow("640x480, 40% occluded, s>=0.5", occluded, "found >= 98%");
  printRow("same, held-out seeds 7000+", occludedHeldOut, "found >= 98%");
  printRow("clutter only, s>=0.7 (found=none)", clutter, "100% with no match");
  printRow("20 instances 1280x1024 (all once)", crowd, "all found, none twice");
  std::printf(
      "\noccluded rows: of the parts missed, %d and %d (held-out) score below the minimum at "
      "their true pose (more than half of the model hidden)\n",
      occluded.hiddenBeyondMinimum, occludedHeldOut.hiddenBeyondMinimum);
  std::printf("\nscale-range time / fixed-scale time: %.2f wall, %.2f CPU (target <= 4)\n",
              median(scale.ms) / median(vga.ms), median(scale.cpu) / median(vga.cpu));
  std::printf(
      "CPU ms = CPU time of all threads (upper bound of the wall time on an idle machine);\n"
      "wall ms depends on the machine's load (load average %.1f at the end of this run).\n",
      loadAverage());
  std::printf(
      "\nOpenCV baselines on the first %d of the same 640x480 scenes (ratios: CPU time, RMS):\n",
      ncc.scenes);
  printBaseline(smoke ? "matchTemplate NCC (smoke: 10 deg)" : "matchTemplate NCC 1 deg", ncc, vga);
  printBaseline("GeneralizedHoughGuil", guil, vga);
  return 0;
}
