#pragma once
// Camera calibration from plate views: camera matrix and lens distortion solved by OpenCV's
// calibrateCamera (the library's solver; facet contributes the subpixel pattern points), and the
// pose of the measuring plane from one view.
//
// Circle-grid views are re-centred with the perspective-correct mark centres
// (circle_marks.hpp) from the previous solution, and solved again, until the camera settles.

#include <string>
#include <vector>

#include <opencv2/core.hpp>

#include "algorithms/calibration/board_spec.hpp"
#include "algorithms/calibration/calibration_failure.hpp"
#include "algorithms/calibration/camera_model.hpp"
#include "algorithms/calibration/pattern_detection.hpp"
#include "algorithms/calibration/world_mapping.hpp"
#include "algorithms/status/status.hpp"

namespace facet {

// One image of the plate as detected.
struct PlateView {
  std::string name;                            // file name, for messages
  PatternDetection detection;                  // status, points
  std::vector<std::vector<cv::Point2d>> rims;  // circle grids: each mark's rim points
};

// Detects the plate in an 8-bit or 16-bit grey image (empty: an image that could not be read).
PlateView detectPlate(const cv::Mat& image, const BoardSpec& board, std::string name);
// detectPlate for many images (names[i] for images[i]), several at once: the views are
// independent, and so the serial parts of OpenCV's grid, blob and marker searches use every core.
std::vector<PlateView> detectPlates(const std::vector<cv::Mat>& images, const BoardSpec& board,
                                    const std::vector<std::string>& names);

struct CalibrationOptions {
  // Fewest views with the pattern found that a calibration accepts. Default 8.
  int minViews = 8;
  // Largest RMS reprojection error over all points, pixels. Default 0.5.
  double maxRmsPx = 0.5;
  // Smallest covered share of the image (0..1) accepted; below `warnCoverage` the result
  // carries a warning. Defaults 0.25 and 0.6.
  double minCoverage = 0.25;
  double warnCoverage = 0.6;
};

struct ViewFit {
  std::string name;
  bool used = false;
  Status<CalibrationFailure> status;          // PatternNotFound: why it cannot be used
  std::string note;                           // used, with a reservation (PatternDetection::note)
  double rmsPx = 0;                           // reprojection RMS of this view's points
  std::vector<cv::Point2d> points;            // detected points
  std::vector<int> ids;                       // their plate point indices (PatternDetection)
  std::vector<cv::Point2d> residuals;         // detected - reprojected, pixels
  cv::Matx33d rotation = cv::Matx33d::eye();  // plate -> camera
  cv::Vec3d translationMm{0, 0, 0};
};

// One distortion model tried by the solver, and what it gave.
struct DistortionCandidate {
  std::string terms;  // "k1,p1,p2", "k1,k2,p1,p2", "k1,k2,p1,p2,k3"
  double rmsPx = 0;
  double bic = 0;  // Bayesian information criterion: the lowest is chosen
  CameraModel camera;
};

struct CameraCalibration {
  Status<CalibrationFailure> status;  // refused: the cause and the reason
  std::string warning;                // accepted with a reservation (coverage)
  CameraModel camera;
  double rmsPx = 0;
  // The distortion terms solved for ("k1,k2,p1,p2" ...): the fewest the points call for.
  std::string distortionModel;
  std::vector<DistortionCandidate> distortionCandidates;
  double coverage = 0;  // covered share of the image, 0..1
  std::vector<ViewFit> views;
};

CameraCalibration calibrateCamera(const BoardSpec& board, cv::Size imageSize,
                                  const std::vector<PlateView>& views,
                                  const CalibrationOptions& options = {});

// The measuring plane from one view of the plate lying where the parts lie (solvePnP on the
// view's points with the calibrated camera); `offsetMm` lifts the plane towards the camera.
// Fails with PatternNotFound (`pose` untouched) when the view has no pattern.
Status<CalibrationFailure> estimatePlanePose(const BoardSpec& board, const CameraModel& camera,
                                             const PlateView& view, double offsetMm,
                                             PlanePose& pose);

}  // namespace facet
