#include "algorithms/edges/edge_linking.hpp"

#include <algorithm>
#include <cmath>
#include <utility>
#include <vector>

namespace facet {
namespace {

// Points come in raster order of their pixels (detectSubpixelEdges scans row by row); an index
// of where each row starts finds a pixel's point by a binary search within its row (a row of a
// large image holds hundreds of points, and linking looks up 8 neighbours per point). Any other
// order is sorted first.
struct PixelIndex {
  int firstRow = 0;
  std::vector<int> rowStart;  // into `order`, one per row + 1
  std::vector<int> order;     // point indices sorted by (y, x)
  const std::vector<cv::Point>* pixels = nullptr;

  explicit PixelIndex(const std::vector<cv::Point>& px) : pixels(&px) {
    order.resize(px.size());
    for (size_t i = 0; i < px.size(); ++i) order[i] = static_cast<int>(i);
    auto before = [&](int a, int b) {
      return px[a].y != px[b].y ? px[a].y < px[b].y : px[a].x < px[b].x;
    };
    if (!std::is_sorted(order.begin(), order.end(), before))
      std::sort(order.begin(), order.end(), before);
    if (px.empty()) return;
    firstRow = px[order.front()].y;
    const int rows = px[order.back()].y - firstRow + 1;
    rowStart.assign(rows + 1, 0);
    for (int i : order) ++rowStart[px[i].y - firstRow + 1];
    for (int r = 0; r < rows; ++r) rowStart[r + 1] += rowStart[r];
  }
  // The points of row y from column x0 on, in order of x: [begin, end) of `order`.
  std::pair<const int*, const int*> rowFrom(int y, int x0) const {
    const int r = y - firstRow;
    if (r < 0 || r + 1 >= static_cast<int>(rowStart.size())) return {nullptr, nullptr};
    const int* first = order.data() + rowStart[r];
    const int* last = order.data() + rowStart[r + 1];
    return {std::lower_bound(first, last, x0, [&](int i, int x) { return (*pixels)[i].x < x; }),
            last};
  }
};

// The next point from `i` in direction `sign` along the tangent, or -1.
int nextPoint(int i, double sign, const std::vector<EdgePoint>& points,
              const std::vector<cv::Point>& pixels, const PixelIndex& index,
              const std::vector<char>& visited, const EdgeLinkParams& params) {
  const EdgePoint& p = points[i];
  const cv::Point2d t = sign * cv::Point2d(-p.normal.y, p.normal.x);
  int best = -1;
  double bestAhead = 0.2;  // must move forward noticeably
  const cv::Point centre = pixels[i];
  // The neighbouring pixels row by row, left to right: one search per row finds all three
  // columns. Of points sharing a pixel the first is that pixel's point.
  for (int dy = -1; dy <= 1; ++dy) {
    int previousX = centre.x - 2;
    for (auto [it, end] = index.rowFrom(centre.y + dy, centre.x - 1);
         it != end && pixels[*it].x <= centre.x + 1; ++it) {
      const int j = *it;
      const int x = std::exchange(previousX, pixels[j].x);
      if (x == pixels[j].x || (dy == 0 && pixels[j].x == centre.x) || visited[j]) continue;
      if (points[j].normal.dot(p.normal) < params.minNormalAgreement) continue;
      const cv::Point2d d = points[j].position - p.position;
      const double ahead = d.dot(t) / std::max(1e-9, std::sqrt(d.x * d.x + d.y * d.y));
      if (ahead > bestAhead) {
        bestAhead = ahead;
        best = j;
      }
    }
  }
  return best;
}

}  // namespace

std::vector<std::vector<int>> linkEdgePoints(const std::vector<EdgePoint>& points,
                                             const std::vector<cv::Point>& pixels,
                                             const EdgeLinkParams& params) {
  const PixelIndex index(pixels);

  std::vector<char> visited(points.size(), 0);
  std::vector<std::vector<int>> contours;
  for (int seed = 0; seed < static_cast<int>(points.size()); ++seed) {
    if (visited[seed]) continue;
    visited[seed] = 1;
    std::vector<int> backward, forward{seed};
    for (int i = seed; (i = nextPoint(i, 1.0, points, pixels, index, visited, params)) >= 0;) {
      visited[i] = 1;
      forward.push_back(i);
    }
    for (int i = seed; (i = nextPoint(i, -1.0, points, pixels, index, visited, params)) >= 0;) {
      visited[i] = 1;
      backward.push_back(i);
    }
    std::reverse(backward.begin(), backward.end());
    backward.insert(backward.end(), forward.begin(), forward.end());
    if (static_cast<int>(backward.size()) >= params.minPoints)
      contours.push_back(std::move(backward));
  }
  return contours;
}

}  // namespace facet
