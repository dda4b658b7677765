#pragma once
// A pixel region stored as runs along rows: what a thin, curved region (the annulus around a
// rim) needs, where its bounding box would be mostly empty.

#include <vector>

#include <opencv2/core.hpp>

namespace facet {

// The pixels x0 <= x < x1 of row y.
struct RowRun {
  int y = 0;
  int x0 = 0;
  int x1 = 0;
};

// Runs sorted by row, then by x0, not overlapping within a row; empty runs are allowed.
using RowRuns = std::vector<RowRun>;

// The pixels of `clip` whose centres lie in the annulus rIn <= |p - centre| <= rOut, one run per
// row or two around the inner disc (rIn = 0: a disc).
RowRuns annulusRowRuns(cv::Point2d centre, double rIn, double rOut, cv::Rect clip);

// The region grown by one pixel in all eight directions (a 3x3 dilation), clipped to `clip`.
RowRuns dilateRowRuns(const RowRuns& runs, cv::Rect clip);

}  // namespace facet
