// bench_calibration: facet's calibration beside OpenCV's pipelines on the same rendered views.
//
// Views: a plate seen through a 1280x1024 camera (fx 1500, k1 -0.22, k2 0.08, tangential terms),
// tilted up to 40 degrees, spread over the field; lens blur sigma 0.7 px before pixel
// integration, noise sigma 2 (tests/support/scene/plane_scene.hpp). Per board kind:
//   facet       facet calibrate's pipeline (subpixel edge corners / perspective-correct marks)
//   cv-classic  findChessboardCorners + cornerSubPix(11x11) + calibrateCamera
//   cv-sb       findChessboardCornersSB(EXHAUSTIVE | ACCURACY) + calibrateCamera
//   cv-circles  findCirclesGrid (blob centres) + calibrateCamera
//   cv-charuco  detectMarkers + interpolateCornersCharuco + calibrateCamera (OpenCV's ChArUco
//               pipeline; 4.6 returns its corners shifted by +0.5 px in x and y, a bug fixed
//               upstream in 2026: cv-charuco-fix is the same with that shift undone)
// Columns: pattern-location error against the renderer's exact projections (RMS px), RMS
// reprojection error, model error (RMS over the field the views cover of the pixel distance
// between where the true and the estimated camera put the same ray, after the best rotation
// between the two cameras), times (detection per view, the solve, and both for all views).
// Then six 6 mm holes in a plane tilted 8 degrees at about 0.14 mm/px (plane pose from one plate
// image, facet's chessboard calibration): centre and diameter errors in um, with the calibration
// and with mm_per_pixel alone (the true scale at the image centre; its centres are given the
// best rigid placement on the truth, which favours it).
//
// Then the model error over --sets view sets (default 8), facet beside cv-classic on the
// chessboard and beside cv-charuco-fix on the ChArUco board: the ratio is judged there
// (see benchSets).
//
// Usage: bench_calibration [--smoke] [--views N] [--seed N] [--sets N] [--save-views DIR]
// --save-views: writes each board's rendered views to DIR/chessboard, DIR/circles and
// DIR/charuco as PNG, so that `facet calibrate` (or a profiler) can be run on exactly the views
// measured here.
// --smoke: 8 chessboard views without lens blur, one hole scene (a few seconds' check).
// --seed 1 (default) is the set the code was developed on; --seed 2 and up are held out.
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <string>
#include <vector>

#include <Eigen/Dense>
#include <opencv2/aruco/charuco.hpp>
#include <opencv2/calib3d.hpp>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "algorithms/calibration/camera_calibration.hpp"
#include "algorithms/calibration/field_coverage.hpp"
#include "algorithms/calibration/plane_circle.hpp"
#include "algorithms/circle/circle_measure.hpp"
#include "tests/calibration/model_error.hpp"
#include "tests/support/scene/calibration_plates.hpp"

namespace {

using namespace facet;
using Clock = std::chrono::steady_clock;
double msSince(Clock::time_point t) {
  return std::chrono::duration<double, std::milli>(Clock::now() - t).count();
}

scene::LensCamera trueCamera() {
  scene::LensCamera c;
  c.fx = 1500, c.fy = 1502, c.cx = 645.2, c.cy = 508.7;
  c.k1 = -0.22, c.k2 = 0.08, c.p1 = 0.0012, c.p2 = -0.0008;
  return c;
}

struct View {
  cv::Mat image;
  std::vector<cv::Point2d> truth;
};

// The ChArUco board: the chessboard's 11 x 8 inner corners, markers 7 mm in 10 mm squares.
constexpr const char* kCharuco = "charuco:12x9:10:7:DICT_5X5_100";
double lensBlur = 0.7;  // --smoke: 0 (renders about 5x faster)
std::string saveViews;  // --save-views DIR: each board's views as PNG, for `facet calibrate`

std::vector<View> renderViews(const BoardSpec& board, int count, std::uint64_t seed) {
  std::vector<View> views;
  const auto camera = trueCamera();
  for (int i = 0; i < count; ++i) {
    scene::PlaneScene s;
    s.camera = camera;
    const bool circles = board.kind == BoardSpec::Kind::Circles;
    s.placement = scene::seriesPlacement(
        camera, {(board.cols - 1) * board.pitchMm, (board.rows - 1) * board.pitchMm},
        circles ? board.pitchMm : 2 * board.pitchMm, seed, i);
    if (board.kind == BoardSpec::Kind::Chessboard)
      scene::addChessboardPlate(s, board.cols, board.rows, board.pitchMm);
    else if (board.kind == BoardSpec::Kind::Charuco)
      scene::addCharucoPlate(s, board.cols + 1, board.rows + 1, board.pitchMm, board.markerMm,
                             board.dictionary);
    else
      scene::addCirclePlate(s, board.cols, board.rows, board.pitchMm, board.diameterMm);
    s.lensBlurSigma = lensBlur;
    s.noiseSigma = 2.0;
    s.seed = seed * 7717 + static_cast<std::uint64_t>(i);
    views.push_back(
        {s.render(), scene::patternImagePoints(s, board.cols, board.rows, board.pitchMm)});
    if (!saveViews.empty()) {
      const char* kinds[] = {"chessboard", "circles", "charuco"};
      const auto folder = std::filesystem::path(saveViews) / kinds[static_cast<int>(board.kind)];
      std::filesystem::create_directories(folder);
      char name[32];
      std::snprintf(name, sizeof name, "view_%02d.png", i);
      cv::imwrite((folder / name).string(), views.back().image);
    }
  }
  return views;
}

// Detected points put into the truth's order by nearest neighbour (OpenCV's detectors may start
// the grid at another corner); empty when a point has no truth within 3 px.
std::vector<cv::Point2d> matchToTruth(const std::vector<cv::Point2d>& found,
                                      const std::vector<cv::Point2d>& truth) {
  std::vector<cv::Point2d> out(truth.size());
  for (std::size_t t = 0; t < truth.size(); ++t) {
    double best = 1e9;
    for (const auto& f : found)
      if (cv::norm(f - truth[t]) < best) best = cv::norm(f - truth[t]), out[t] = f;
    if (best > 3) return {};
  }
  return out;
}

struct Row {
  std::string method;
  int found = 0, views = 0;
  double locationRms = 0, reprojRms = 0, modelRms = 0, detectMs = 0, solveMs = 0;
  CameraModel camera;
};

double modelError(const CameraModel& est, const scene::LensCamera& truth, const cv::Mat& covered) {
  return test::modelError(est, {truth.matrix(), truth.distortion(), truth.size}, covered);
}

// `ids[v]`: the plate point index of each of points[v] (empty: all points in plate order).
Row solveAndScore(const std::string& method, const BoardSpec& board,
                  const std::vector<std::vector<cv::Point2d>>& points,
                  const std::vector<std::vector<int>>& ids, const std::vector<View>& views,
                  const cv::Mat& covered, double detectMs) {
  Row row{method};
  row.views = static_cast<int>(views.size());
  std::vector<std::vector<cv::Point3f>> objects;
  std::vector<std::vector<cv::Point2f>> images;
  const auto plate = board.platePoints();
  double sum = 0;
  int n = 0;
  for (std::size_t v = 0; v < views.size(); ++v) {
    if (points[v].empty()) continue;
    ++row.found;
    std::vector<cv::Point3f> o;
    for (std::size_t i = 0; i < points[v].size(); ++i, ++n) {
      const auto id = ids[v].empty() ? i : static_cast<std::size_t>(ids[v][i]);
      o.emplace_back(plate[id]);
      sum += std::pow(cv::norm(points[v][i] - views[v].truth[id]), 2);
    }
    objects.push_back(o);
    images.emplace_back(points[v].begin(), points[v].end());
  }
  row.locationRms = std::sqrt(sum / std::max(n, 1));
  row.detectMs = detectMs / static_cast<double>(views.size());
  if (row.found < 3) return row;
  const auto t0 = Clock::now();
  cv::Mat K, D;
  std::vector<cv::Mat> rv, tv;
  row.reprojRms = cv::calibrateCamera(
      objects, images, views[0].image.size(), K, D, rv, tv, 0,
      cv::TermCriteria(cv::TermCriteria::COUNT + cv::TermCriteria::EPS, 100, 1e-12));
  row.solveMs = msSince(t0);
  row.camera = {cv::Matx33d(K), D.reshape(1, 1).clone(), views[0].image.size()};
  row.modelRms = modelError(row.camera, trueCamera(), covered);
  return row;
}

std::vector<Row> benchBoard(const BoardSpec& board, int count, std::uint64_t seed,
                            CameraModel& facetCamera, bool withSb = true) {
  const auto views = renderViews(board, count, seed);
  std::vector<std::vector<cv::Point2d>> outlines;
  for (const auto& v : views) outlines.push_back(gridOutline(v.truth, board.cols, board.rows));
  const cv::Mat covered = coveredField(views[0].image.size(), outlines);
  std::vector<Row> rows;

  // facet: its own detection and its own calibration (circle grids re-centred per round).
  {
    auto t0 = Clock::now();
    // As `facet calibrate` does: every view searched, several at once.
    std::vector<cv::Mat> images;
    std::vector<std::string> names;
    for (std::size_t i = 0; i < views.size(); ++i)
      images.push_back(views[i].image), names.push_back(std::to_string(i));
    const std::vector<PlateView> plate = detectPlates(images, board, names);
    const double detect = msSince(t0);
    t0 = Clock::now();
    CalibrationOptions options;
    options.minViews = 3;
    const auto c = calibrateCamera(board, views[0].image.size(), plate, options);
    Row row{"facet"};
    row.solveMs = msSince(t0);
    row.views = count;
    row.detectMs = detect / count;
    double sum = 0;
    int n = 0;
    for (std::size_t v = 0; v < c.views.size(); ++v) {
      if (!c.views[v].used) continue;
      ++row.found;
      const ViewFit& fit = c.views[v];
      for (std::size_t i = 0; i < fit.points.size(); ++i, ++n) {
        const auto id = fit.ids.empty() ? i : static_cast<std::size_t>(fit.ids[i]);
        sum += std::pow(cv::norm(fit.points[i] - views[v].truth[id]), 2);
      }
    }
    row.locationRms = std::sqrt(sum / std::max(n, 1));
    row.reprojRms = c.rmsPx;
    if (c.status.ok()) {
      row.camera = c.camera;
      row.modelRms = modelError(c.camera, trueCamera(), covered);
      facetCamera = c.camera;
    } else {
      std::printf("facet calibration refused: %s\n", c.status.message.c_str());
    }
    rows.push_back(row);
  }
  const cv::Size grid(board.cols, board.rows);
  if (board.kind == BoardSpec::Kind::Chessboard) {
    std::vector<std::vector<cv::Point2d>> classic, sb;
    auto t0 = Clock::now();
    for (const auto& v : views) {
      std::vector<cv::Point2f> f;
      if (cv::findChessboardCorners(v.image, grid, f,
                                    cv::CALIB_CB_ADAPTIVE_THRESH | cv::CALIB_CB_NORMALIZE_IMAGE)) {
        cv::cornerSubPix(v.image, f, {11, 11}, {-1, -1},
                         {cv::TermCriteria::EPS + cv::TermCriteria::COUNT, 30, 0.001});
        classic.push_back(matchToTruth({f.begin(), f.end()}, v.truth));
      } else {
        classic.emplace_back();
      }
    }
    const std::vector<std::vector<int>> inOrder(views.size());
    rows.push_back(
        solveAndScore("cv-classic", board, classic, inOrder, views, covered, msSince(t0)));
    if (!withSb) return rows;
    t0 = Clock::now();
    for (const auto& v : views) {
      std::vector<cv::Point2f> f;
      if (cv::findChessboardCornersSB(v.image, grid, f,
                                      cv::CALIB_CB_EXHAUSTIVE | cv::CALIB_CB_ACCURACY))
        sb.push_back(matchToTruth({f.begin(), f.end()}, v.truth));
      else
        sb.emplace_back();
    }
    rows.push_back(solveAndScore("cv-sb", board, sb, inOrder, views, covered, msSince(t0)));
  } else if (board.kind == BoardSpec::Kind::Charuco) {
    const auto dictionary = cv::aruco::getPredefinedDictionary(board.dictionary);
    const auto cvBoard = cv::aruco::CharucoBoard::create(
        board.cols + 1, board.rows + 1, static_cast<float>(board.pitchMm),
        static_cast<float>(board.markerMm), dictionary);
    std::vector<std::vector<cv::Point2d>> corners, fixed;
    std::vector<std::vector<int>> ids;
    const auto t0 = Clock::now();
    for (const auto& v : views) {
      std::vector<std::vector<cv::Point2f>> markers;
      std::vector<int> markerIds, cornerIds;
      std::vector<cv::Point2f> found;
      cv::aruco::detectMarkers(v.image, dictionary, markers, markerIds);
      if (!markerIds.empty())
        cv::aruco::interpolateCornersCharuco(markers, markerIds, v.image, cvBoard, found,
                                             cornerIds);
      if (found.size() < 8) found.clear(), cornerIds.clear();
      corners.emplace_back(found.begin(), found.end());
      ids.push_back(cornerIds);
    }
    const double detect = msSince(t0);
    rows.push_back(solveAndScore("cv-charuco", board, corners, ids, views, covered, detect));
    for (auto points : corners) {
      for (auto& p : points) p -= cv::Point2d(0.5, 0.5);
      fixed.push_back(points);
    }
    rows.push_back(solveAndScore("cv-charuco-fix", board, fixed, ids, views, covered, detect));
  } else {
    std::vector<std::vector<cv::Point2d>> blobs;
    auto t0 = Clock::now();
    cv::SimpleBlobDetector::Params params;
    params.maxArea = 1e5;
    const auto detector = cv::SimpleBlobDetector::create(params);
    for (const auto& v : views) {
      std::vector<cv::Point2f> f;
      if (cv::findCirclesGrid(v.image, grid, f, cv::CALIB_CB_SYMMETRIC_GRID, detector))
        blobs.push_back(matchToTruth({f.begin(), f.end()}, v.truth));
      else
        blobs.emplace_back();
    }
    rows.push_back(solveAndScore("cv-circles", board, blobs,
                                 std::vector<std::vector<int>>(views.size()), views, covered,
                                 msSince(t0)));
  }
  return rows;
}

// model/cv: against rows[baseline] (OpenCV's classic pipeline; for ChArUco its corrected corners,
// the stricter baseline).
void printRows(const std::string& board, const std::vector<Row>& rows, std::size_t baseline = 1) {
  std::printf("\n%s\n%-14s %7s %12s %12s %12s %10s %10s %9s %9s\n", board.c_str(), "method",
              "views", "location px", "reproj px", "model px", "model/cv", "detect ms", "solve ms",
              "total s");
  const double cv = rows[std::min(baseline, rows.size() - 1)].modelRms;
  for (const auto& r : rows)
    std::printf("%-14s %3d/%-3d %12.4f %12.4f %12.4f %10.2f %10.0f %9.0f %9.2f\n", r.method.c_str(),
                r.found, r.views, r.locationRms, r.reprojRms, r.modelRms, r.modelRms / cv,
                r.detectMs, r.solveMs, (r.detectMs * r.views + r.solveMs) / 1000.0);
  const Row& f = rows.front();
  const double total = (f.detectMs * f.views + f.solveMs) / 1000.0;
  std::printf(
      "facet: %d views calibrated in %.2f s (detection of every view and the solve); "
      "target for 20 views <= 2 s: %s\n",
      f.views, total, f.views < 20 ? "n/a" : (total <= 2.0 ? "met" : "MISSED"));
}

// Six 6 mm holes in a part lying where the plate lay: facet's calibration + plane from one
// plate image vs mm_per_pixel alone.
void benchHoles(const CameraModel& calibrated, std::uint64_t seed, bool smoke) {
  const auto camera = trueCamera();
  const BoardSpec board{BoardSpec::Kind::Chessboard, 11, 8, 10.0, 0.0};
  std::printf(
      "\nsix 6 mm holes, plane tilted 8 deg, blur 0.7 px, noise 2 (errors in um; "
      "px-equivalent at the plane's scale in brackets)\n");
  std::printf("%-6s %22s %22s %22s %22s\n", "scene", "centre calibrated", "diameter calibrated",
              "centre mm/px only", "diameter mm/px only");
  double sc = 0, sd = 0, pc = 0, pd = 0;
  int n = 0;
  double scale = 0;
  const int scenes = smoke ? 1 : 4;
  for (int k = 0; k < scenes; ++k) {
    const auto placement = scene::lookAtPlane({0, 0}, 212, 8, 30 + 70 * k, 5 * k, camera);
    // The plate, laid where the parts lie, for the plane pose.
    scene::PlaneScene plate;
    plate.camera = camera;
    plate.placement = placement;
    plate.placement.translationMm = placement.toCamera({-50, -35});  // plate origin, centred
    scene::addChessboardPlate(plate, board.cols, board.rows, board.pitchMm);
    plate.lensBlurSigma = lensBlur, plate.noiseSigma = 2,
    plate.seed = seed * 31 + static_cast<std::uint64_t>(k);
    PlanePose pose;
    const auto plane =
        estimatePlanePose(board, calibrated, detectPlate(plate.render(), board, "plane"), 0, pose);
    if (!plane.ok()) {
      std::printf("plane not found: %s\n", plane.message.c_str());
      return;
    }
    const WorldMapping mapping(calibrated, pose);
    // The part: holes at plate coordinates (the plate frame is the plane frame).
    scene::PlaneScene part;
    part.camera = camera;
    part.placement = plate.placement;
    part.addPolygon({{-25, -30}, {125, -30}, {125, 100}, {-25, 100}}, 210);
    std::vector<cv::Point2d> holes;
    for (int j = 0; j < 2; ++j)
      for (int i = 0; i < 3; ++i) holes.push_back({-12.0 + 62.0 * i, -22.0 + 114.0 * j});
    for (const auto& h : holes) part.addDisc(h, 3.0, 30);
    part.lensBlurSigma = lensBlur, part.noiseSigma = 2,
    part.seed = seed * 97 + static_cast<std::uint64_t>(k);
    const cv::Mat image = part.render();
    const scene::LensCamera& c = camera;
    const CameraModel truthModel{c.matrix(), c.distortion(), c.size};
    const WorldMapping truthMapping(truthModel,
                                    {part.placement.rotation, part.placement.translationMm, 0});
    scale = truthMapping.mmPerPixelAt({639.5, 511.5});
    std::vector<cv::Point2d> imageCentres, trueCentres;
    std::vector<double> imageDiameters;
    double kc = 0, kd = 0;
    for (const auto& h : holes) {
      CircleMeasureParams p;
      const cv::Point2d guess = part.imageOf(h);
      p.centre = guess + cv::Point2d(0.7, -0.4);
      p.radius = 3.0 / scale;
      p.width = 5;
      p.polarity = CirclePolarity::DarkToLight;
      const auto m = measureCircle(image, p);
      const auto w = circleInPlane(m, mapping);
      if (!w) {
        std::printf("hole at (%.0f, %.0f) mm not measured: %s\n", h.x, h.y,
                    m.status.message.c_str());
        continue;
      }
      const double ec = cv::norm(w->centreMm - h) * 1000, ed = (w->diameterMm - 6.0) * 1000;
      sc += ec * ec, sd += ed * ed, kc += ec * ec, kd += ed * ed;
      imageCentres.push_back(m.centre);
      imageDiameters.push_back(m.diameter);
      trueCentres.push_back(h);
      ++n;
    }
    // mm_per_pixel alone: scaled image centres, best rigid placement on the truth.
    std::vector<cv::Point2d> scaled;
    for (const auto& q : imageCentres) scaled.push_back(q * scale);
    cv::Point2d ms(0, 0), mt(0, 0);
    for (std::size_t i = 0; i < scaled.size(); ++i) ms += scaled[i], mt += trueCentres[i];
    ms /= double(scaled.size()), mt /= double(scaled.size());
    double sxx = 0, sxy = 0;
    for (std::size_t i = 0; i < scaled.size(); ++i) {
      const cv::Point2d a = scaled[i] - ms, b = trueCentres[i] - mt;
      sxx += a.x * b.x + a.y * b.y, sxy += a.x * b.y - a.y * b.x;
    }
    const double angle = std::atan2(sxy, sxx);
    double qc = 0, qd = 0;
    for (std::size_t i = 0; i < scaled.size(); ++i) {
      const cv::Point2d a = scaled[i] - ms;
      const cv::Point2d r(std::cos(angle) * a.x - std::sin(angle) * a.y,
                          std::sin(angle) * a.x + std::cos(angle) * a.y);
      const double ec = cv::norm(r + mt - trueCentres[i]) * 1000,
                   ed = (imageDiameters[i] * scale - 6.0) * 1000;
      pc += ec * ec, pd += ed * ed, qc += ec * ec, qd += ed * ed;
    }
    const double m6 = static_cast<double>(imageCentres.size());
    std::printf("%-6d %22.1f %22.1f %22.1f %22.1f\n", k, std::sqrt(kc / m6), std::sqrt(kd / m6),
                std::sqrt(qc / m6), std::sqrt(qd / m6));
  }
  const double um = scale * 1000;
  std::printf("RMS    %13.1f (%.4f) %13.1f (%.4f) %13.1f (%.3f) %13.1f (%.3f)   [%.4f mm/px]\n",
              std::sqrt(sc / n), std::sqrt(sc / n) / um, std::sqrt(sd / n), std::sqrt(sd / n) / um,
              std::sqrt(pc / n), std::sqrt(pc / n) / um, std::sqrt(pd / n), std::sqrt(pd / n) / um,
              scale);
}

// The model error of one set of views is one draw of the detection noise: 30 redraws of noise
// with the size of facet's own corner errors, on seed 2's views, give a model error of 0.0042 px
// on average, between 0.001 and 0.01, and OpenCV's classic pipeline swings from 0.003 to 0.02
// over seeds 1-3. So the ratio is judged on the RMS over several sets, each rendered with its
// own seed (the first is the set of the table above). cv-sb (15-40 s per set) is left out.
void benchSets(const BoardSpec& board, int count, std::uint64_t seed, int sets,
               const std::vector<Row>& first, std::size_t baseline) {
  const std::string cv = first[baseline].method;
  std::printf("\nmodel error over %d view sets of %s (seeds %llu-%llu; RMS over the sets)\n", sets,
              board.text().c_str(), static_cast<unsigned long long>(seed),
              static_cast<unsigned long long>(seed + static_cast<std::uint64_t>(sets) - 1));
  std::printf("%-6s %12s %14s %10s\n", "seed", "facet px", (cv + " px").c_str(), "facet/cv");
  double sf = 0, sc = 0, hf = 0, hc = 0;  // h: the held-out sets (seed 1 was developed on)
  for (int k = 0; k < sets; ++k) {
    CameraModel unused;
    const std::uint64_t s = seed + static_cast<std::uint64_t>(k);
    const std::vector<Row> rows = k == 0 ? first : benchBoard(board, count, s, unused, false);
    const double f = rows[0].modelRms, c = rows[baseline].modelRms;
    sf += f * f, sc += c * c;
    if (s != 1) hf += f * f, hc += c * c;
    std::printf("%-6llu %12.4f %14.4f %10.2f\n", static_cast<unsigned long long>(s), f, c, f / c);
  }
  if (seed == 1 && sets > 2)
    std::printf("%-6s %12.4f %14.4f %10.2f   (held-out sets only)\n", "RMS",
                std::sqrt(hf / (sets - 1)), std::sqrt(hc / (sets - 1)), std::sqrt(hf / hc));
  const double rf = std::sqrt(sf / sets), rc = std::sqrt(sc / sets);
  std::printf("%-6s %12.4f %14.4f %10.2f   target <= 0.02 px and <= 0.5 of %s: %s\n", "RMS", rf, rc,
              rf / rc, cv.c_str(), rf <= 0.02 && rf <= 0.5 * rc ? "met" : "MISSED");
}

}  // namespace

int main(int argc, char** argv) {
  bool smoke = false;
  int count = 20, sets = 8;
  std::uint64_t seed = 1;
  for (int i = 1; i < argc; ++i) {
    if (!std::strcmp(argv[i], "--smoke"))
      smoke = true;
    else if (!std::strcmp(argv[i], "--views") && i + 1 < argc)
      count = std::atoi(argv[++i]);
    else if (!std::strcmp(argv[i], "--seed") && i + 1 < argc)
      seed = std::strtoull(argv[++i], nullptr, 10);
    else if (!std::strcmp(argv[i], "--sets") && i + 1 < argc)
      sets = std::atoi(argv[++i]);
    else if (!std::strcmp(argv[i], "--save-views") && i + 1 < argc)
      saveViews = argv[++i];
    else {
      std::fprintf(stderr,
                   "usage: bench_calibration [--smoke] [--views N] [--seed N] [--sets N] "
                   "[--save-views DIR]\n");
      return 1;
    }
  }
  std::setvbuf(stdout, nullptr, _IOLBF, 0);
  if (smoke) count = 8, lensBlur = 0;
  std::printf("bench_calibration: %d views per board, 1280x1024, seed %llu%s\n", count,
              static_cast<unsigned long long>(seed), smoke ? " (smoke)" : "");
  CameraModel chessCamera, circleCamera;
  const BoardSpec chess{BoardSpec::Kind::Chessboard, 11, 8, 10.0, 0.0};
  const std::vector<Row> chessRows = benchBoard(chess, count, seed, chessCamera);
  std::vector<Row> charucoRows;
  printRows("chessboard:11x8:10", chessRows);
  if (!smoke) {
    const BoardSpec circles{BoardSpec::Kind::Circles, 9, 7, 12.0, 6.0};
    printRows("circles:9x7:12:6", benchBoard(circles, count, seed, circleCamera));
    std::string why;
    const auto charuco = parseBoardSpec(kCharuco, why);
    CameraModel charucoCamera;
    charucoRows = benchBoard(*charuco, count, seed, charucoCamera);
    printRows(kCharuco, charucoRows, 2);
  }
  if (chessCamera.imageSize.empty()) return 1;
  benchHoles(chessCamera, seed, smoke);
  if (!smoke && sets > 1) {
    benchSets(chess, count, seed, sets, chessRows, 1);
    std::string why;
    benchSets(*parseBoardSpec(kCharuco, why), count, seed, sets, charucoRows, 2);
  }
  return 0;
}
