#include "algorithms/calibration/pattern_detection.hpp"

namespace facet {

std::vector<cv::Point3d> PatternDetection::platePoints(const BoardSpec& board) const {
  std::vector<cv::Point3d> all = board.platePoints();
  if (ids.empty()) return all;
  std::vector<cv::Point3d> seen;
  seen.reserve(ids.size());
  for (int id : ids) seen.push_back(all[static_cast<std::size_t>(id)]);
  return seen;
}

}  // namespace facet
