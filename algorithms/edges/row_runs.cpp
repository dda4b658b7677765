#include "algorithms/edges/row_runs.hpp"

#include <algorithm>

namespace facet {

RowRuns dilateRowRuns(const RowRuns& runs, cv::Rect clip) {
  RowRuns out;
  if (runs.empty() || clip.empty()) return out;
  const int yFirst = std::max(clip.y, runs.front().y - 1);
  const int yLast = std::min(clip.y + clip.height - 1, runs.back().y + 1);
  std::vector<RowRun> row;  // the grown runs of the three rows around one output row
  std::size_t from = 0;     // first run of row y - 1 or later
  for (int y = yFirst; y <= yLast; ++y) {
    while (from < runs.size() && runs[from].y < y - 1) ++from;
    row.clear();
    for (std::size_t i = from; i < runs.size() && runs[i].y <= y + 1; ++i) {
      const int x0 = std::max(clip.x, runs[i].x0 - 1);
      const int x1 = std::min(clip.x + clip.width, runs[i].x1 + 1);
      if (runs[i].x0 < runs[i].x1 && x0 < x1) row.push_back({y, x0, x1});
    }
    std::sort(row.begin(), row.end(), [](const RowRun& a, const RowRun& b) { return a.x0 < b.x0; });
    for (const RowRun& r : row) {
      if (!out.empty() && out.back().y == y && r.x0 <= out.back().x1)
        out.back().x1 = std::max(out.back().x1, r.x1);
      else
        out.push_back(r);
    }
  }
  return out;
}

}  // namespace facet
