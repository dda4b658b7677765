#pragma once
// Fiducials located by registration: the recipe's reference image with the marks' positions is
// registered to the live image (with params.model); each mark is carried through H,
// and the part's rotation and scale come from the similarity fitted to the carried marks.

#include <string>
#include <vector>

#include <opencv2/core.hpp>

#include "algorithms/registration/register_images.hpp"
#include "algorithms/registration/registration_failure.hpp"
#include "algorithms/status/status.hpp"

namespace facet {

struct FiducialResult {
  Status<RegistrationFailure> status;  // as RegistrationResult's, or TooFewFiducials
  std::vector<cv::Point2d> marks;      // image positions, same order as the reference marks
  double rotationDeg = 0;              // part rotation, counter-clockwise on screen (Pose2D)
  double scale = 1;
  cv::Matx33d H = cv::Matx33d::eye();  // reference -> image
};

// `refMarks`: two or more mark positions in the reference image (pixels).
FiducialResult locateFiducials(const cv::Mat& ref, const std::vector<cv::Point2d>& refMarks,
                               const cv::Mat& image, RegistrationParams params = {});

}  // namespace facet
