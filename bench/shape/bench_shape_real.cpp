// bench_shape_real: findShapeModel as a user gets it (default model, default search) beside a
// pyramid NCC matcher (pyramid_ncc.hpp) in the same run:
//   1. speed on generated bracket scenes, the first search after loading a model file ("cold")
//      and the next ones ("warm"; also the fastest of a few repeats, in CPU and in wall time,
//      with the share of the CPU time a virtual machine's host took meanwhile), and a 4096x3000
//      photograph with a large template;
//   2. the real photographs of tests/data/photos (cases.txt): found / missed / false and the
//      pose's distance from the independent reference, per image; beside facet's defaults, the
//      earlier defaults (every model on the profile fit; every edge contour kept) and a
//      deformation tolerance of 1 px.
//
//   bench_shape_real [--smoke] [--data DIR] [--speed-only | --photos-only] [--greediness G]
//                    [--min-score S]  (the photographs searched at another minimum score)
// Times are medians of the process's CPU time (all threads), ms, on this machine, but for the
// column that says wall.

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <ctime>
#include <filesystem>
#include <fstream>
#include <numbers>
#include <sstream>
#include <string>
#include <vector>

#include <unistd.h>

#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "algorithms/shape/find_shape_model.hpp"
#include "algorithms/shape/shape_model.hpp"
#include "algorithms/shape/shape_model_file.hpp"
#include "bench/shape/pyramid_ncc.hpp"
#include "tests/shape/bracket_scenes.hpp"
#include "tests/shape/photo_occlusion.hpp"

namespace {

using namespace facet;

// CPU time of the whole process (all threads), ms: on a shared, loaded machine the wall time
// measures the other jobs; CPU time is an upper bound of the wall time on an idle machine
// (the search runs on at most 2 threads by default).
double cpuMs() {
  timespec t{};
  clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &t);
  return t.tv_sec * 1e3 + t.tv_nsec / 1e6;
}

// Wall time, ms: what a line waits for; beside the CPU time for the repeated warm search only
// (the machine otherwise idle).
double wallMs() {
  return std::chrono::duration<double, std::milli>(
             std::chrono::steady_clock::now().time_since_epoch())
      .count();
}

struct Stopwatch {
  double start = cpuMs();
};

double msSince(const Stopwatch& t0) {
  return cpuMs() - t0.start;
}

double median(std::vector<double> v) {
  if (v.empty()) return NAN;
  std::nth_element(v.begin(), v.begin() + v.size() / 2, v.end());
  return v[v.size() / 2];
}

// --- 1. Speed with the defaults -------------------------------------------------------------

struct SpeedRow {
  std::vector<double> cold, warm, warmBest, warmWallBest, greedy, ncc;
  int found = 0, nccFound = 0, scenes = 0;
};

bool near(double x, double y, double angle, const Pose2D& truth) {
  return std::hypot(x - truth.x, y - truth.y) < 2.0 &&
         std::abs(degrees(wrapAngle(angle - truth.angle))) < 1.5;
}

// Each warm search is repeated this many times for the "best of" column.
constexpr int kRepeats = 5;

// The machine's CPU time counters (/proc/stat: all time and the time a hypervisor took from
// this virtual machine, "steal"), to say how much of the speed rows' time the host took.
struct CpuCounters {
  double total = 0.0, stolen = 0.0;
};

CpuCounters cpuCounters() {
  std::ifstream in("/proc/stat");
  std::string cpu;
  CpuCounters c;
  in >> cpu;
  for (int i = 0; i < 8 && in; ++i) {
    double v = 0.0;
    in >> v;
    c.total += v;
    if (i == 7) c.stolen = v;
  }
  return c;
}

void speedRow(const char* name, cv::Size size, int scenes, const std::filesystem::path& modelFile,
              const cv::Mat& templ, bool withNcc, const char* target) {
  SpeedRow row;
  for (int i = 0; i < scenes; ++i) {
    const double u = (i * 0.618034) - std::floor(i * 0.618034);
    const Pose2D truth{size.width * (0.3 + 0.4 * u), size.height * (0.35 + 0.3 * (1 - u)),
                       (2 * u - 1) * std::numbers::pi, 1.0};
    const cv::Mat image = testing::bracketScene(size, {truth}, 500 + i);
    // Cold: the first search after loading the model file; warm: the next search, on another
    // image (the same part elsewhere), as on a line.
    const Pose2D next{size.width - truth.x, size.height - truth.y, wrapAngle(truth.angle + 2.0),
                      1.0};
    const cv::Mat nextImage = testing::bracketScene(size, {next}, 900 + i);
    const ShapeModel model = loadShapeModel(modelFile);
    {
      const Stopwatch t0;
      const auto m = findShapeModel(image, model);
      row.cold.push_back(msSince(t0));
      row.found += !m.empty() && near(m[0].x, m[0].y, m[0].angle, truth);
    }
    {
      const double wall0 = wallMs();
      const Stopwatch t0;
      const auto m = findShapeModel(nextImage, model);
      row.warm.push_back(msSince(t0));
      double wallBest = wallMs() - wall0;
      row.found += !m.empty() && near(m[0].x, m[0].y, m[0].angle, next);
      // The same search again, the fastest of kRepeats: what the search costs when the host
      // takes nothing from it (on a virtual machine it takes time while the search runs, and the
      // process is charged for it; see CpuCounters). In CPU time and in wall time: the second
      // thread's share of the CPU time is not all time the line waits.
      double best = row.warm.back();
      for (int r = 1; r < kRepeats; ++r) {
        const double wall0 = wallMs();
        const Stopwatch t1;
        (void)findShapeModel(nextImage, model);
        best = std::min(best, msSince(t1));
        wallBest = std::min(wallBest, wallMs() - wall0);
      }
      row.warmBest.push_back(best);
      row.warmWallBest.push_back(wallBest);
    }
    {
      // The former default: greediness 0.9 (faster, but can drop clear parts).
      FindParams greedy;
      greedy.greediness = 0.9;
      const Stopwatch t0;
      (void)findShapeModel(image, model, greedy);
      row.greedy.push_back(msSince(t0));
    }
    if (withNcc) {
      const Stopwatch t0;
      const auto n = bench::findByPyramidNcc(image, templ, 1);
      row.ncc.push_back(msSince(t0));
      row.nccFound += !n.empty() && near(n[0].x, n[0].y, radians(n[0].angleDeg), truth);
    }
    ++row.scenes;
  }
  std::printf(
      "| %-24s | %3d | %3d/%d | %7.2f | %7.2f | %7.2f | %7.2f | %7.2f | %3d/%d | %8.2f | %6.1f | "
      "%s |\n",
      name, row.scenes, row.found, 2 * row.scenes, median(row.cold), median(row.warm),
      median(row.warmBest), median(row.warmWallBest), median(row.greedy), row.nccFound, row.scenes,
      median(row.ncc), median(row.ncc) / median(row.warm), target);
}

// The large case: a photograph of a circuit board, enlarged to 4096x3000 and turned; the
// template is its large chip (about 1100x950 pixels).
void largeRow(const std::filesystem::path& data, int repeats) {
  const cv::Mat board =
      cv::imread((data / "board_qfp100_template.png").string(), cv::IMREAD_GRAYSCALE);
  const cv::Mat photo = cv::imread((data / "board_source.jpg").string(), cv::IMREAD_GRAYSCALE);
  if (board.empty() || photo.empty()) {
    std::printf("| 4096x3000 photograph     | (missing %s) |\n", data.c_str());
    return;
  }
  const double f = 6.4;
  cv::Mat big, scene;
  cv::resize(photo, big, {4096, 3072}, 0, 0, cv::INTER_CUBIC);
  big = big(cv::Rect(0, 36, 4096, 3000)).clone();
  const cv::Point2f centre(2047.5f, 1499.5f);
  const double angle = 21.0;
  const cv::Mat m = cv::getRotationMatrix2D(centre, angle, 1.0);
  cv::warpAffine(big, scene, m, big.size(), cv::INTER_LINEAR, cv::BORDER_REFLECT);
  // The template: the chip's region of the enlarged photograph (board_qfp100 at 332,292 176x152).
  const cv::Rect roi(cvRound(332 * f), cvRound(292 * f - 36), cvRound(176 * f), cvRound(152 * f));
  const cv::Mat templ = big(roi).clone();
  const cv::Point2d rc(roi.x + (roi.width - 1) / 2.0, roi.y + (roi.height - 1) / 2.0);
  const Pose2D truth{m.at<double>(0, 0) * rc.x + m.at<double>(0, 1) * rc.y + m.at<double>(0, 2),
                     m.at<double>(1, 0) * rc.x + m.at<double>(1, 1) * rc.y + m.at<double>(1, 2),
                     radians(angle), 1.0};
  Stopwatch t0;
  const ShapeModel model = createShapeModel(templ);
  const double createMs = msSince(t0);
  std::vector<double> ours, ncc;
  bool found = false, nccFound = false;
  for (int i = 0; i < repeats; ++i) {
    t0 = Stopwatch();
    const auto r = findShapeModel(scene, model);
    ours.push_back(msSince(t0));
    found = !r.empty() && near(r[0].x, r[0].y, r[0].angle, truth);
    t0 = Stopwatch();
    const auto n = bench::findByPyramidNcc(scene, templ, 1);
    ncc.push_back(msSince(t0));
    nccFound = !n.empty() && near(n[0].x, n[0].y, radians(n[0].angleDeg), truth);
  }
  std::printf(
      "| 4096x3000, %4dx%-4d tmpl | %3d | %3d/1 | %7s | %7.1f | %7s | %7s | %7s | %3d/1 | %8.1f "
      "| %6.1f | faster than NCC (model %.0f ms, %d levels) |\n",
      templ.cols, templ.rows, repeats, int(found), "-", median(ours), "-", "-", "-", int(nccFound),
      median(ncc), median(ncc) / median(ours), createMs, model.numLevels());
}

// --- 2. Real photographs ----------------------------------------------------------------------

struct PhotoCase {
  std::string name, templ, scene, method;
  int period = 360;
  std::vector<Pose2D> refs;
};

std::vector<PhotoCase> readCases(const std::filesystem::path& file) {
  std::vector<PhotoCase> out;
  std::ifstream in(file);
  std::string line;
  while (std::getline(in, line)) {
    if (line.empty() || line[0] == '#') continue;
    std::istringstream s(line);
    PhotoCase c;
    int n = 0;
    s >> c.name >> c.templ >> c.scene >> c.period >> n;
    for (int i = 0; i < n; ++i) {
      double x, y, a, sc;
      s >> x >> y >> a >> sc;
      c.refs.push_back({x, y, radians(a), sc});
    }
    s >> c.method;
    if (s) out.push_back(c);
  }
  return out;
}

struct Tally {
  int found = 0, missed = 0, falses = 0;
  double worstPos = 0.0, worstAngle = 0.0;
  double lowestScore = NAN;  // of the matches found
};

// Matches within 3 px (and 2 degrees, modulo the case's period) of a reference are found.
template <typename M>
Tally tally(const PhotoCase& c, const std::vector<M>& matches, auto xOf, auto yOf, auto angleOf) {
  Tally t;
  std::vector<bool> used(c.refs.size(), false);
  for (const auto& m : matches) {
    bool hit = false;
    for (std::size_t i = 0; i < c.refs.size() && !hit; ++i) {
      const double dp = std::hypot(xOf(m) - c.refs[i].x, yOf(m) - c.refs[i].y);
      double da = degrees(wrapAngle(angleOf(m) - c.refs[i].angle));
      if (c.period == 180) da = std::min(std::abs(da), 180.0 - std::abs(da));
      if (c.period == 0) da = 0.0;
      if (used[i] || c.refs[i].scale == 0.0 || dp > 3.0 || std::abs(da) > 2.0) continue;
      used[i] = hit = true;
      t.worstPos = std::max(t.worstPos, dp);
      t.worstAngle = std::max(t.worstAngle, std::abs(da));
      t.lowestScore = std::isnan(t.lowestScore) ? m.score : std::min(t.lowestScore, m.score);
    }
    // Near an optional reference (a part cut by the image border, scale 0): not counted.
    bool optional = false;
    for (const auto& r : c.refs)
      optional |= r.scale == 0.0 && std::hypot(xOf(m) - r.x, yOf(m) - r.y) < 3.0;
    t.found += hit;
    t.falses += !hit && !optional;
  }
  int required = 0;
  for (const auto& r : c.refs) required += r.scale > 0.0;
  t.missed = required - t.found;
  return t;
}

void photoTable(const std::filesystem::path& data, bool smoke, const FindParams& base) {
  const auto cases = readCases(data / "cases.txt");
  std::printf(
      "\n| photograph | refs | method | facet found/missed/false | facet worst pos px, "
      "angle deg | facet lowest score found | facet ms | NCC found/missed/false | NCC worst pos "
      "px, angle deg | NCC "
      "ms | edges chosen (training test px: profile / zero crossing) | profile fit only: "
      "found/missed/false, worst pos px, angle deg "
      "| max deformation 1: found/missed/false, worst pos px, ms "
      "| every contour (min component 0, the earlier default): found/missed/false, worst pos px, "
      "lowest score "
      "|\n|---|---|---|---|---|---|---|---|---|---|---|---|---|---|\n");
  Tally sum, nccSum, profileSum, deformedSum, everySum;
  for (const auto& c : cases) {
    const cv::Mat templ = cv::imread((data / c.templ).string(), cv::IMREAD_GRAYSCALE);
    const cv::Mat scene = cv::imread((data / c.scene).string(), cv::IMREAD_GRAYSCALE);
    if (templ.empty() || scene.empty()) {
      std::printf("| %s | cannot read its files |\n", c.name.c_str());
      continue;
    }
    const ShapeModel model = createShapeModel(templ);
    // The earlier default, every model on the profile fit, in the same run.
    ShapeModelParams profileParams;
    profileParams.edgeEstimator = EdgeEstimator::ProfileFit;
    const ShapeModel profileModel = createShapeModel(templ, profileParams);
    // The earlier default too: every edge contour kept, specks and all.
    ShapeModelParams everyParams;
    everyParams.minComponentSize = 0;
    const ShapeModel everyModel = createShapeModel(templ, everyParams);
    const auto refCount = static_cast<int>(
        std::count_if(c.refs.begin(), c.refs.end(), [](const Pose2D& r) { return r.scale > 0.0; }));
    FindParams p = base;
    p.numMatches = 0;  // all above the default minimum score
    Stopwatch t0;
    const auto ours = findShapeModel(scene, model, p);
    const double ms = msSince(t0);
    const Tally t = tally(
        c, ours, [](auto& m) { return m.x; }, [](auto& m) { return m.y; },
        [](auto& m) { return m.angle; });
    const Tally pf = tally(
        c, findShapeModel(scene, profileModel, p), [](auto& m) { return m.x; },
        [](auto& m) { return m.y; }, [](auto& m) { return m.angle; });
    const Tally ev = tally(
        c, findShapeModel(scene, everyModel, p), [](auto& m) { return m.x; },
        [](auto& m) { return m.y; }, [](auto& m) { return m.angle; });
    // The deformation tolerance a user sets for parts that differ from their template by a pixel
    // or two: what it finds, and what it costs, on every photograph.
    FindParams tolerant = p;
    tolerant.maxDeformation = 1;
    t0 = Stopwatch();
    const auto deformed = findShapeModel(scene, model, tolerant);
    const double deformedMs = msSince(t0);
    const Tally d = tally(
        c, deformed, [](auto& m) { return m.x; }, [](auto& m) { return m.y; },
        [](auto& m) { return m.angle; });
    double trial[2] = {NAN, NAN};
    for (const EdgeEstimatorTrial& e : model.edgeEstimatorTrials)
      trial[e.estimator == EdgeEstimator::ProfileFit ? 0 : 1] = e.poseError;
    Tally n;
    double nccMs = NAN;
    if (!smoke) {
      t0 = Stopwatch();
      const auto theirs = bench::findByPyramidNcc(scene, templ, refCount, 0.6);
      nccMs = msSince(t0);
      n = tally(
          c, theirs, [](auto& m) { return m.x; }, [](auto& m) { return m.y; },
          [](auto& m) { return radians(m.angleDeg); });
    }
    std::printf(
        "| %s (%d levels) | %d | %s | %d/%d/%d | %.2f, %.2f | %.3f | %.1f | %d/%d/%d | %.2f, %.2f "
        "| "
        "%.1f | %s (%.3f / %.3f) | %d/%d/%d, %.2f, %.2f | %d/%d/%d, %.2f, %.1f | %d/%d/%d, %.2f, "
        "%.3f |\n",
        c.name.c_str(), model.numLevels(), refCount, c.method.c_str(), t.found, t.missed, t.falses,
        t.worstPos, t.worstAngle, t.lowestScore, ms, n.found, n.missed, n.falses, n.worstPos,
        n.worstAngle, nccMs, edgeEstimatorName(model.edgeEstimator), trial[0], trial[1], pf.found,
        pf.missed, pf.falses, pf.worstPos, pf.worstAngle, d.found, d.missed, d.falses, d.worstPos,
        deformedMs, ev.found, ev.missed, ev.falses, ev.worstPos, ev.lowestScore);
    everySum.found += ev.found, everySum.missed += ev.missed, everySum.falses += ev.falses;
    deformedSum.found += d.found, deformedSum.missed += d.missed, deformedSum.falses += d.falses;
    profileSum.found += pf.found, profileSum.missed += pf.missed, profileSum.falses += pf.falses;
    sum.found += t.found, sum.missed += t.missed, sum.falses += t.falses;
    nccSum.found += n.found, nccSum.missed += n.missed, nccSum.falses += n.falses;
  }
  std::printf("| all | | | %d/%d/%d | | | | %d/%d/%d | | | | %d/%d/%d | %d/%d/%d | %d/%d/%d |\n",
              sum.found, sum.missed, sum.falses, nccSum.found, nccSum.missed, nccSum.falses,
              profileSum.found, profileSum.missed, profileSum.falses, deformedSum.found,
              deformedSum.missed, deformedSum.falses, everySum.found, everySum.missed,
              everySum.falses);
}

// The photographs with an exact reference (method "warp": the scene is the photograph turned and
// shifted by a known pose), each with a third of the part hidden, from each of its four sides in
// turn, behind a flat grey plate (the photograph's median grey, anti-aliased border): real
// texture beside an occluder's straight border, which can stand in for a hidden edge of the
// part. Minimum score 0.5 for both matchers, as in bench_shape's occluded rows.
void occludedPhotoTable(const std::filesystem::path& data, bool smoke) {
  std::printf(
      "\n| photograph, a third hidden from each side | scenes | facet found | facet pos RMS px | "
      "facet pos max px | NCC found | NCC pos RMS px | NCC pos max px | facet pos px: left, right, "
      "top, bottom hidden |\n"
      "|---|---|---|---|---|---|---|---|---|\n");
  auto rms = [](const std::vector<double>& v) {
    double s = 0;
    for (double e : v) s += e * e;
    return v.empty() ? NAN : std::sqrt(s / static_cast<double>(v.size()));
  };
  auto worst = [](const std::vector<double>& v) {
    return v.empty() ? NAN : *std::max_element(v.begin(), v.end());
  };
  std::vector<double> allOurs, allNcc;
  int scenes = 0;
  for (const auto& c : readCases(data / "cases.txt")) {
    if (c.method != "warp" || c.refs.size() != 1) continue;
    const cv::Mat templ = cv::imread((data / c.templ).string(), cv::IMREAD_GRAYSCALE);
    const cv::Mat scene = cv::imread((data / c.scene).string(), cv::IMREAD_GRAYSCALE);
    if (templ.empty() || scene.empty()) continue;
    const ShapeModel model = createShapeModel(templ);
    const Pose2D& truth = c.refs[0];
    std::vector<double> ours, ncc;
    std::string perSide;
    int n = 0;
    for (const testing::HiddenSide side : testing::kHiddenSides) {
      if (smoke && n > 0) break;
      const cv::Mat hidden = testing::hideSide(scene, templ.size(), truth, side);
      ++n;
      FindParams p;
      p.minScore = 0.5;
      const auto m = findShapeModel(hidden, model, p);
      const bool hit = !m.empty() && near(m[0].x, m[0].y, m[0].angle, truth);
      if (hit) ours.push_back(std::hypot(m[0].x - truth.x, m[0].y - truth.y));
      perSide += (n > 1 ? ", " : "") + (hit ? cv::format("%.3f", ours.back()) : std::string("-"));
      if (!smoke) {
        const auto t = bench::findByPyramidNcc(hidden, templ, 1, 0.5);
        if (!t.empty() && near(t[0].x, t[0].y, radians(t[0].angleDeg), truth))
          ncc.push_back(std::hypot(t[0].x - truth.x, t[0].y - truth.y));
      }
    }
    const std::string nccFound = smoke ? "not run" : std::to_string(ncc.size());
    std::printf("| %s | %d | %zu | %.3f | %.3f | %s | %.3f | %.3f | %s |\n", c.name.c_str(), n,
                ours.size(), rms(ours), worst(ours), nccFound.c_str(), rms(ncc), worst(ncc),
                perSide.c_str());
    scenes += n;
    allOurs.insert(allOurs.end(), ours.begin(), ours.end());
    allNcc.insert(allNcc.end(), ncc.begin(), ncc.end());
  }
  std::printf("| all | %d | %zu | %.3f | | %zu | %.3f | | |\n", scenes, allOurs.size(),
              rms(allOurs), allNcc.size(), rms(allNcc));
}

}  // namespace

int main(int argc, char** argv) {
  std::setvbuf(stdout, nullptr, _IOLBF, 0);  // rows appear as they are measured
  bool smoke = false, photosOnly = false, speedOnly = false;
  FindParams photoParams;  // the defaults; --greediness G, --min-score S to compare
  std::filesystem::path data = std::filesystem::path(FACET_SOURCE_DIR) / "tests/data/photos";
  for (int i = 1; i < argc; ++i) {
    if (!std::strcmp(argv[i], "--smoke")) smoke = true;
    if (!std::strcmp(argv[i], "--data") && i + 1 < argc) data = argv[++i];
    if (!std::strcmp(argv[i], "--greediness") && i + 1 < argc)
      photoParams.greediness = std::atof(argv[++i]);
    if (!std::strcmp(argv[i], "--min-score") && i + 1 < argc)
      photoParams.minScore = std::atof(argv[++i]);
    if (!std::strcmp(argv[i], "--photos-only")) photosOnly = true;
    if (!std::strcmp(argv[i], "--speed-only")) speedOnly = true;
  }
  const cv::Mat templ = testing::bracketTemplate();
  // One file per process: two runs at once must not remove each other's model.
  const auto modelFile = std::filesystem::temp_directory_path() /
                         ("bench_shape_real." + std::to_string(getpid()) + ".model");
  {
    const ShapeModel model = createShapeModel(templ);
    saveShapeModel(model, modelFile);
    std::printf("bench_shape_real%s: default bracket model, %d levels, %zu points\n",
                smoke ? " --smoke" : "", model.numLevels(), model.levels[0].points.size());
  }
  {
    // The process's very first search (thread pool, first allocations), for the record.
    const ShapeModel model = loadShapeModel(modelFile);
    const cv::Mat image = testing::bracketScene({640, 480}, {{320, 240, 0.3, 1.0}}, 1);
    const Stopwatch t0;
    (void)findShapeModel(image, model);
    std::printf("first search of the process: %.2f ms\n", msSince(t0));
  }
  if (photosOnly) {
    photoTable(data, smoke, photoParams);
    occludedPhotoTable(data, smoke);
    std::filesystem::remove(modelFile);
    return 0;
  }
  const int scenes = smoke ? 2 : 20;
  std::printf(
      "\n| defaults, bracket scenes | scenes | found | cold ms | warm ms | warm ms, best of %d "
      "| warm wall ms, best of %d | warm ms, greediness 0.9 | NCC found | NCC ms | NCC / warm "
      "| target |\n|---|---|---|---|---|---|---|---|---|---|---|---|\n",
      kRepeats, kRepeats);
  const CpuCounters before = cpuCounters();
  speedRow("640x480, 360 deg", {640, 480}, scenes, modelFile, templ, true,
           "<= 4 ms warm, <= 6 ms cold");
  speedRow("1280x1024, 360 deg", {1280, 1024}, scenes, modelFile, templ, !smoke, "<= 8 ms");
  if (!smoke) largeRow(data, 1);
  double load[1] = {NAN};
  getloadavg(load, 1);
  const CpuCounters after = cpuCounters();
  const double span = after.total - before.total;
  std::printf(
      "load average at the end of the speed rows: %.1f; CPU time the host took from this "
      "machine meanwhile (steal): %.1f%% of all its CPUs' time\n",
      load[0], span > 0.0 ? 100.0 * (after.stolen - before.stolen) / span : NAN);
  if (!speedOnly) {
    photoTable(data, smoke, photoParams);
    occludedPhotoTable(data, smoke);
  }
  std::filesystem::remove(modelFile);
  return 0;
}
