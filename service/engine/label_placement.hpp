#pragma once
// Where the text labels of an overlay go: inside the picture (below the verdict banner), clear
// of each other, and as close to the point they describe as the room allows. Labels that were
// drawn at their anchor ran off the right edge and covered each other where features sit close.

#include <vector>

#include <opencv2/core.hpp>

namespace facet::service {

struct LabelRequest {
  cv::Point2d anchor;  // the point the label describes, picture pixels
  cv::Size size;       // the label's box, pixels
};

// One box per request, in the same order. Each lies inside [0, picture.width) x [top,
// picture.height) when it fits there at all, and overlaps no earlier box while a free place is
// left; earlier labels get the better places.
std::vector<cv::Rect> placeLabels(cv::Size picture, int top,
                                  const std::vector<LabelRequest>& labels);

}  // namespace facet::service
