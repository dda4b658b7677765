#pragma once
// Whether a shape model's search, with all of its pyramid levels, finds the model's own part
// wherever the part lands on the camera's grid. The automatic pyramid (ShapeModelParams::numLevels
// = 0) is built from the edges each level keeps, less the top levels on which the part's pattern
// repeats within the search's reach (findSearchPeriods, model_symmetry.hpp: a chessboard's
// squares, aliased at 1/8). This test, whose answer is known, then turns levels down while that
// loses fewer copies: it catches what neither rule sees (an apple, whose upper levels see a
// nearly round outline and leave the part's angle and place further off than the levels below
// look; small print, whose top level keeps too little of the part's score to trust).

#include <opencv2/core.hpp>

#include "algorithms/shape/shape_model.hpp"

namespace facet {

// The number of turned, shifted copies of the template that `model`'s search loses: it returns a
// pose more than a pixel from the copy's known one, scoring lower than that pose scores, or
// nothing where that pose reaches the search's default minimum score; or would lose were the
// copy to score only the minimum: the top level scores the known pose below the share of level
// 0's score the search assumes there (level_search.hpp, kTopFactor; lines of small print, whose
// letters blur into rows at 1/4, keep 0.57 of it). The copies are turned
// across the model's angle range and shifted across a pixel of its top level (every phase of
// the coarse grid). `templateImage` is the trained region, the model's reference point in its
// pixels; where it is a region of a larger image, the copies show that image around it.
int copiesLostBySearch(const cv::Mat& templateImage, const ShapeModel& model);

}  // namespace facet
