#pragma once
// Whether a shape model's search, with all of its pyramid levels, finds the model's own part
// wherever the part lands on the camera's grid. A coarse level sees a periodic pattern (a
// chessboard's squares, a connector's pins) aliased: at some turns and sub-pixel phases the
// part's own pose scores lower there than a neighbouring period's, is suppressed, and the search
// returns the neighbour though the part scores higher at level 0 (a chessboard patch: the top
// level 1/8 of the part's size, a square 1.6 px there; 0.954 returned, the part 0.999). The
// automatic pyramid (ShapeModelParams::numLevels = 0) is built from the edges each level keeps;
// this test, whose answer is known, then turns levels down while that loses fewer copies.

#include <opencv2/core.hpp>

#include "algorithms/shape/shape_model.hpp"

namespace facet {

// The number of turned, shifted copies of the template that `model`'s search loses: it returns a
// pose more than a pixel from the copy's known one, scoring lower than that pose scores, or
// nothing where that pose reaches the search's default minimum score. The copies are turned
// across the model's angle range and shifted across a pixel of its top level (every phase of
// the coarse grid). `templateImage` is the trained region, the model's reference point in its
// pixels; where it is a region of a larger image, the copies show that image around it.
int copiesLostBySearch(const cv::Mat& templateImage, const ShapeModel& model);

}  // namespace facet
