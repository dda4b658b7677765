#include "algorithms/edges/edge_linking.hpp"

#include <algorithm>
#include <unordered_map>

namespace facet {
namespace {

struct PixelIndex {
  std::unordered_map<long long, int> map;
  static long long key(cv::Point p) {
    return (static_cast<long long>(p.y) << 32) ^ static_cast<unsigned int>(p.x);
  }
  int find(cv::Point p) const {
    const auto it = map.find(key(p));
    return it == map.end() ? -1 : it->second;
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
  for (int dy = -1; dy <= 1; ++dy)
    for (int dx = -1; dx <= 1; ++dx) {
      if (dx == 0 && dy == 0) continue;
      const int j = index.find(pixels[i] + cv::Point(dx, dy));
      if (j < 0 || visited[j]) continue;
      if (points[j].normal.dot(p.normal) < params.minNormalAgreement) continue;
      const cv::Point2d d = points[j].position - p.position;
      const double ahead = d.dot(t) / std::max(1e-9, std::hypot(d.x, d.y));
      if (ahead > bestAhead) {
        bestAhead = ahead;
        best = j;
      }
    }
  return best;
}

}  // namespace

std::vector<std::vector<int>> linkEdgePoints(const std::vector<EdgePoint>& points,
                                             const std::vector<cv::Point>& pixels,
                                             const EdgeLinkParams& params) {
  PixelIndex index;
  index.map.reserve(points.size() * 2);
  for (int i = 0; i < static_cast<int>(points.size()); ++i)
    index.map[PixelIndex::key(pixels[i])] = i;

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
