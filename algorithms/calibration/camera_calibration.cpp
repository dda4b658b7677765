#include "algorithms/calibration/camera_calibration.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <sstream>

#include <opencv2/calib3d.hpp>
#include <opencv2/core/utility.hpp>

#include "algorithms/calibration/charuco_corners.hpp"
#include "algorithms/calibration/chessboard_corners.hpp"
#include "algorithms/calibration/circle_marks.hpp"
#include "algorithms/calibration/field_coverage.hpp"

namespace facet {
namespace {

std::vector<cv::Point3f> plateFloat(const std::vector<cv::Point3d>& plate) {
  return {plate.begin(), plate.end()};
}

std::vector<cv::Point2f> imageFloat(const std::vector<cv::Point2d>& points) {
  return {points.begin(), points.end()};
}

struct Solution {
  CameraModel camera;
  double rms = 0;
  std::vector<cv::Mat> rvecs, tvecs;
  std::string distortionModel;
  std::vector<DistortionCandidate> candidates;  // every model tried
};

// The distortion models tried, simplest first. A narrow lens sees too little of its own field
// for k3 (or even k2) to be told apart from k1: fitted anyway they follow the noise and bend the
// model outside the views. The model is chosen by the Bayesian information criterion, so a
// term stays only when it explains the points better than its cost in freedom.
struct DistortionModel {
  const char* name;
  int flags;
  int terms;
};
constexpr DistortionModel kDistortionModels[] = {
    {"k1,p1,p2", cv::CALIB_FIX_K2 | cv::CALIB_FIX_K3, 3},
    {"k1,k2,p1,p2", cv::CALIB_FIX_K3, 4},
    {"k1,k2,p1,p2,k3", 0, 5},
};

// The solver stops once an iteration changes the parameters by less than this share of their
// size. At 1e-8 the camera is the one a 1e-12 limit gives to within 1e-7 px of model error
// (chessboard, circle grid and ChArUco series of bench_calibration), in half the solve time.
constexpr double kSolverStep = 1e-8;

// Solves with every distortion model and keeps the one the criterion prefers; with `only`, with
// that model alone (the re-centring rounds of circle marks, which move points by hundredths of a
// pixel and would not change the choice). `start`: a solution of these points a moment ago (the
// same rounds): the solver starts from its camera matrix, not from OpenCV's own guess.
// `plate[k]`: the plate points of view k's `points[k]`.
Solution solve(cv::Size size, const std::vector<std::vector<cv::Point3d>>& plate,
               const std::vector<std::vector<cv::Point2d>>& points, const std::string& only = {},
               const CameraModel* start = nullptr) {
  // OpenCV wants float points; float keeps 1e-4 px at 2000 px, two orders below the noise.
  std::vector<std::vector<cv::Point3f>> objects;
  std::vector<std::vector<cv::Point2f>> images;
  std::size_t count = 0;
  for (std::size_t k = 0; k < points.size(); ++k) {
    objects.push_back(plateFloat(plate[k]));
    images.push_back(imageFloat(points[k]));
    count += points[k].size();
  }
  const double n = 2.0 * static_cast<double>(count);  // residual components
  Solution best;
  std::vector<DistortionCandidate> candidates;
  double bestBic = std::numeric_limits<double>::infinity();
  // Each richer model starts from the simpler one's solution (its new terms at zero): near the
  // optimum already, its solver needs fewer rounds than from OpenCV's own start.
  cv::Mat guessK, guessD;
  if (start) {
    // The camera matrix only: a distortion term the model holds fixed would be held at the
    // start's value, not at zero.
    guessK = cv::Mat(start->cameraMatrix).clone();
    guessD = cv::Mat::zeros(1, 5, CV_64F);
  }
  for (const DistortionModel& model : kDistortionModels) {
    if (!only.empty() && only != model.name) continue;
    Solution s;
    cv::Mat K = guessK.clone(), D = guessD.clone();
    s.rms = cv::calibrateCamera(
        objects, images, size, K, D, s.rvecs, s.tvecs,
        model.flags | (guessK.empty() ? 0 : cv::CALIB_USE_INTRINSIC_GUESS),
        cv::TermCriteria(cv::TermCriteria::COUNT + cv::TermCriteria::EPS, 100, kSolverStep));
    guessK = K, guessD = D;
    s.camera.cameraMatrix = cv::Matx33d(K);
    s.camera.distortion = D.reshape(1, 1).clone();
    s.camera.imageSize = size;
    s.distortionModel = model.name;
    // The per-view poses are the same in every model and cancel out.
    const double rss = s.rms * s.rms * static_cast<double>(count);
    const double bic = n * std::log(std::max(rss, 1e-300) / n) + (4 + model.terms) * std::log(n);
    candidates.push_back({model.name, s.rms, bic, s.camera});
    if (bic < bestBic) bestBic = bic, best = std::move(s);
  }
  best.candidates = std::move(candidates);
  return best;
}

cv::Matx33d rotationOf(const cv::Mat& rvec) {
  cv::Mat R;
  cv::Rodrigues(rvec, R);
  return cv::Matx33d(R);
}

std::string percent(double share) {
  std::ostringstream o;
  o.precision(0);
  o << std::fixed << 100 * share << "%";
  return o.str();
}

}  // namespace

PlateView detectPlate(const cv::Mat& image, const BoardSpec& board, std::string name) {
  PlateView view;
  view.name = std::move(name);
  if (image.empty()) {
    view.detection.status.message = "cannot read the image (unknown format or corrupt)";
    return view;
  }
  if (board.kind == BoardSpec::Kind::Chessboard) {
    view.detection = detectChessboard(image, board);
  } else if (board.kind == BoardSpec::Kind::Charuco) {
    view.detection = detectCharuco(image, board);
  } else {
    CircleMarks marks = detectCircleMarks(image, board);
    view.detection = std::move(marks.detection);
    view.rims = std::move(marks.rims);
  }
  return view;
}

std::vector<PlateView> detectPlates(const std::vector<cv::Mat>& images, const BoardSpec& board,
                                    const std::vector<std::string>& names) {
  std::vector<PlateView> views(images.size());
  cv::parallel_for_(cv::Range(0, static_cast<int>(images.size())), [&](const cv::Range& range) {
    for (int i = range.start; i < range.end; ++i) {
      const auto k = static_cast<std::size_t>(i);
      views[k] = detectPlate(images[k], board, names[k]);
    }
  });
  return views;
}

CameraCalibration calibrateCamera(const BoardSpec& board, cv::Size imageSize,
                                  const std::vector<PlateView>& views,
                                  const CalibrationOptions& options) {
  CameraCalibration out;
  std::vector<std::size_t> used;
  for (std::size_t i = 0; i < views.size(); ++i) {
    ViewFit fit;
    fit.name = views[i].name;
    fit.status = views[i].detection.status;
    fit.points = views[i].detection.points;
    fit.ids = views[i].detection.ids;
    fit.note = views[i].detection.note;
    if (views[i].detection.status.ok()) used.push_back(i);
    out.views.push_back(std::move(fit));
  }
  if (static_cast<int>(used.size()) < options.minViews) {
    out.status = Status<CalibrationFailure>::failed(
        CalibrationFailure::TooFewViews, "the pattern was found in " + std::to_string(used.size()) +
                                             " of " + std::to_string(views.size()) +
                                             " images; at least " +
                                             std::to_string(options.minViews) + " are needed");
    return out;
  }
  std::vector<std::vector<cv::Point2d>> points, outlines;
  std::vector<std::vector<cv::Point3d>> plate;
  for (std::size_t i : used) {
    const PatternDetection& d = views[i].detection;
    points.push_back(d.points);
    plate.push_back(d.platePoints(board));
    outlines.push_back(patternOutline(d.points, d.ids, board.cols, board.rows));
  }
  out.coverage = coveredShare(coveredField(imageSize, outlines));
  if (out.coverage < options.minCoverage) {
    out.status = Status<CalibrationFailure>::failed(
        CalibrationFailure::CoverageTooSmall,
        "the views cover " + percent(out.coverage) + " of the image; at least " +
            percent(options.minCoverage) + " are needed (move the plate into the corners)");
    return out;
  }
  if (out.coverage < options.warnCoverage)
    out.warning = "the views cover only " + percent(out.coverage) +
                  " of the image: the lens model is extrapolated outside them";

  Solution s = solve(imageSize, plate, points);
  if (board.kind == BoardSpec::Kind::Circles) {
    // Re-centre every mark with the perspective-correct centre of the current solution; the
    // model is chosen again only on the final centres.
    const std::string chosen = s.distortionModel;
    constexpr int kRounds = 4;
    for (int round = 0; round < kRounds; ++round) {
      double moved = 0;
      for (std::size_t k = 0; k < used.size(); ++k) {
        CircleMarks marks{views[used[k]].detection, views[used[k]].rims};
        auto centres = perspectiveCentres(marks, s.camera, rotationOf(s.rvecs[k]));
        for (std::size_t j = 0; j < centres.size(); ++j)
          moved = std::max(moved, cv::norm(centres[j] - points[k][j]));
        points[k] = std::move(centres);
      }
      if (moved < 1e-4 || round + 1 == kRounds) break;
      s = solve(imageSize, plate, points, chosen, &s.camera);
    }
    s = solve(imageSize, plate, points, {}, &s.camera);
  }
  out.camera = s.camera;
  out.rmsPx = s.rms;
  out.distortionModel = s.distortionModel;
  out.distortionCandidates = s.candidates;
  for (std::size_t k = 0; k < used.size(); ++k) {
    ViewFit& fit = out.views[used[k]];
    fit.used = true;
    fit.points = points[k];
    fit.rotation = rotationOf(s.rvecs[k]);
    fit.translationMm = cv::Vec3d(s.tvecs[k].ptr<double>());
    double sum = 0;
    for (std::size_t j = 0; j < plate[k].size(); ++j) {
      const cv::Point3d& q = plate[k][j];
      const cv::Vec3d c = fit.rotation * cv::Vec3d(q.x, q.y, q.z) + fit.translationMm;
      const cv::Point2d r = points[k][j] - s.camera.project(c);
      fit.residuals.push_back(r);
      sum += r.dot(r);
    }
    fit.rmsPx = std::sqrt(sum / static_cast<double>(plate[k].size()));
  }
  if (out.rmsPx > options.maxRmsPx) {
    out.status = Status<CalibrationFailure>::failed(
        CalibrationFailure::RmsTooLarge,
        "the RMS reprojection error is " + std::to_string(out.rmsPx) + " px, above the limit of " +
            std::to_string(options.maxRmsPx) +
            " px (wrong square size, a bent plate, or motion blur?)");
    return out;
  }
  return out;
}

Status<CalibrationFailure> estimatePlanePose(const BoardSpec& board, const CameraModel& camera,
                                             const PlateView& view, double offsetMm,
                                             PlanePose& pose) {
  if (!view.detection.status.ok())
    return Status<CalibrationFailure>::failed(CalibrationFailure::PatternNotFound,
                                              view.name + ": " + view.detection.status.message);
  std::vector<cv::Point2d> points = view.detection.points;
  cv::Mat rvec, tvec;
  std::vector<cv::Point3d> plate = view.detection.platePoints(board);
  const cv::Mat K(camera.cameraMatrix);
  cv::solvePnP(plate, points, K, camera.distortion, rvec, tvec, false, cv::SOLVEPNP_IPPE);
  if (board.kind == BoardSpec::Kind::Circles) {
    CircleMarks marks{view.detection, view.rims};
    points = perspectiveCentres(marks, camera, rotationOf(rvec));
  }
  cv::solvePnPRefineLM(
      plate, points, K, camera.distortion, rvec, tvec,
      cv::TermCriteria(cv::TermCriteria::COUNT + cv::TermCriteria::EPS, 100, 1e-12));
  pose.rotation = rotationOf(rvec);
  pose.translationMm = cv::Vec3d(tvec.ptr<double>());
  pose.offsetMm = offsetMm;
  return {};
}

}  // namespace facet
