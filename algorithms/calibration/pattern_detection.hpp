#pragma once
// PatternDetection: where a calibration plate's points lie in one image.

#include <string>
#include <vector>

#include <opencv2/core.hpp>

namespace facet {

struct PatternDetection {
  bool found = false;
  std::string why;                  // when not found: the reason, for the user
  std::vector<cv::Point2d> points;  // image pixels, in BoardSpec::platePoints() order
};

}  // namespace facet
