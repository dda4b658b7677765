#pragma once
// Linking subpixel edge points into contours.
//
// Points are linked through the 8-neighbourhood of the pixels they came from. From each point
// the walk continues to the unvisited neighbouring point that lies furthest ahead along the edge
// tangent (t = (-ny, nx), which keeps the light side on the same hand) and whose normal agrees
// with the current one; a contour is walked forwards and backwards from its seed, so open
// contours come out from one end to the other and closed ones once round.

#include <vector>

#include <opencv2/core.hpp>

#include "algorithms/edges/subpixel_edges.hpp"

namespace facet {

struct EdgeLinkParams {
  double minNormalAgreement = 0.5;  // cos of the largest normal turn between linked points
  int minPoints = 1;                // shorter contours are dropped (their points stay)
};

// `pixels[i]` is the pixel point i came from. Returns contours as index lists into `points`.
std::vector<std::vector<int>> linkEdgePoints(const std::vector<EdgePoint>& points,
                                             const std::vector<cv::Point>& pixels,
                                             const EdgeLinkParams& params = {});

}  // namespace facet
