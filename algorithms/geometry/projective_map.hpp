#pragma once
// A point carried through a 3x3 projective map (homography, affine map or similarity written
// as a homography): q = (H p) / (H p)_z.

#include <opencv2/core.hpp>

namespace facet {

[[nodiscard]] inline cv::Point2d mapPoint(const cv::Matx33d& H, cv::Point2d p) {
  const double w = H(2, 0) * p.x + H(2, 1) * p.y + H(2, 2);
  return {(H(0, 0) * p.x + H(0, 1) * p.y + H(0, 2)) / w,
          (H(1, 0) * p.x + H(1, 1) * p.y + H(1, 2)) / w};
}

}  // namespace facet
