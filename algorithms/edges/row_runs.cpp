#include "algorithms/edges/row_runs.hpp"

#include <algorithm>
#include <cmath>

namespace facet {

RowRuns annulusRowRuns(cv::Point2d centre, double rIn, double rOut, cv::Rect clip) {
  RowRuns runs;
  const int xLo = clip.x, xHi = clip.x + clip.width - 1;
  for (int y = clip.y; y < clip.y + clip.height; ++y) {
    // Per row: the pixels with |x - cx| <= outer and not |x - cx| < inner. The bounds come from
    // square roots; each is then moved to where the per-pixel test itself changes, so the runs
    // hold exactly the pixels that test accepts.
    const double dy = y - centre.y;
    if (std::abs(dy) > rOut) continue;
    const double outer = std::sqrt(rOut * rOut - dy * dy);
    const double inner = std::abs(dy) < rIn ? std::sqrt(rIn * rIn - dy * dy) : -1.0;
    const int xa = std::max(xLo, static_cast<int>(std::ceil(centre.x - outer)));
    const int xb = std::min(xHi, static_cast<int>(std::floor(centre.x + outer)));
    if (xa > xb) continue;
    auto hole = [&](int x) { return std::abs(x - centre.x) < inner; };
    // The inner disc's pixels on this row: [h0, h1) (empty when the row misses it).
    int h0 = static_cast<int>(std::ceil(centre.x - inner)), h1 = h0;
    if (inner > 0.0) {
      while (h0 > xa && hole(h0 - 1)) --h0;
      while (h0 <= xb && !hole(h0) && h0 < centre.x) ++h0;
      if (h0 <= xb && hole(h0)) {
        h1 = std::max(h0 + 1, static_cast<int>(std::floor(centre.x + inner)) + 1);
        while (h1 > h0 + 1 && !hole(h1 - 1)) --h1;
        while (h1 <= xb && hole(h1)) ++h1;
      }
    }
    if (h1 == h0) {
      runs.push_back({y, xa, xb + 1});
      continue;
    }
    if (xa < h0) runs.push_back({y, xa, std::min(h0, xb + 1)});
    if (h1 <= xb) runs.push_back({y, std::max(h1, xa), xb + 1});
  }
  return runs;
}

RowRuns dilateRowRuns(const RowRuns& runs, cv::Rect clip) {
  RowRuns out;
  if (runs.empty() || clip.empty()) return out;
  const int yFirst = std::max(clip.y, runs.front().y - 1);
  const int yLast = std::min(clip.y + clip.height - 1, runs.back().y + 1);
  const int xEnd = clip.x + clip.width;
  out.reserve(runs.size() + static_cast<std::size_t>(yLast - yFirst + 1));
  std::size_t from = 0;  // first run of row y - 1 or later
  for (int y = yFirst; y <= yLast; ++y) {
    while (from < runs.size() && runs[from].y < y - 1) ++from;
    // The runs of rows y - 1, y and y + 1, each sorted by x0 already: merged by x0 (a run's grown
    // start only depends on its start), they come in the order a sort of all of them would give.
    std::size_t next[3], end[3];
    std::size_t i = from;
    for (int k = 0; k < 3; ++k) {
      next[k] = i;
      while (i < runs.size() && runs[i].y == y - 1 + k) ++i;
      end[k] = i;
    }
    for (;;) {
      int first = -1;
      for (int k = 0; k < 3; ++k)
        if (next[k] < end[k] && (first < 0 || runs[next[k]].x0 < runs[next[first]].x0)) first = k;
      if (first < 0) break;
      const RowRun& run = runs[next[first]++];
      const int x0 = std::max(clip.x, run.x0 - 1);
      const int x1 = std::min(xEnd, run.x1 + 1);
      if (run.x0 >= run.x1 || x0 >= x1) continue;
      if (!out.empty() && out.back().y == y && x0 <= out.back().x1)
        out.back().x1 = std::max(out.back().x1, x1);
      else
        out.push_back({y, x0, x1});
    }
  }
  return out;
}

}  // namespace facet
