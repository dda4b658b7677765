#include "service/engine/label_placement.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

namespace facet::service {
namespace {

// Moves `box` inside the area, keeping its size (when the area is smaller, at its top left).
cv::Rect clampInto(cv::Rect box, const cv::Rect& area) {
  box.x = std::max(area.x, std::min(box.x, area.x + area.width - box.width));
  box.y = std::max(area.y, std::min(box.y, area.y + area.height - box.height));
  return box;
}

// Labels keep a gap between them and from the picture's edges, so that each reads on its own.
constexpr int kGap = 2;

bool overlapsAny(const cv::Rect& box, const std::vector<cv::Rect>& placed) {
  const cv::Rect grown(box.x - kGap, box.y - kGap, box.width + 2 * kGap, box.height + 2 * kGap);
  return std::any_of(placed.begin(), placed.end(),
                     [&](const cv::Rect& other) { return (grown & other).area() > 0; });
}

double distance(const cv::Rect& box, cv::Point2d p) {
  const double dx = std::max({box.x - p.x, 0.0, p.x - (box.x + box.width)});
  const double dy = std::max({box.y - p.y, 0.0, p.y - (box.y + box.height)});
  return std::hypot(dx, dy);
}

}  // namespace

std::vector<cv::Rect> placeLabels(cv::Size picture, int top,
                                  const std::vector<LabelRequest>& labels) {
  const cv::Rect area(kGap, top + kGap, std::max(1, picture.width - 2 * kGap),
                      std::max(1, picture.height - top - 2 * kGap));
  std::vector<cv::Rect> placed;
  placed.reserve(labels.size());
  for (const auto& label : labels) {
    const int w = label.size.width, h = label.size.height;
    const int ax = static_cast<int>(std::lround(label.anchor.x));
    const int ay = static_cast<int>(std::lround(label.anchor.y));
    // Beside the anchor first (right, left, above, below), then anywhere on a grid of the
    // label's own size, nearest to the anchor.
    std::vector<cv::Rect> candidates{{ax, ay - h, w, h},
                                     {ax, ay, w, h},
                                     {ax - w, ay - h, w, h},
                                     {ax - w, ay, w, h},
                                     {ax - w / 2, ay - h - 4, w, h},
                                     {ax - w / 2, ay + 4, w, h}};
    // At most 64 x 64 grid places: a label is looked for, not optimised.
    const int stepX = std::max({4, w / 4, area.width / 64});
    const int stepY = std::max({2, h / 2, area.height / 64});
    std::vector<cv::Rect> grid;
    for (int y = area.y; y + h <= area.y + area.height; y += stepY)
      for (int x = area.x; x + w <= area.x + area.width; x += stepX) grid.push_back({x, y, w, h});
    std::stable_sort(grid.begin(), grid.end(), [&](const cv::Rect& a, const cv::Rect& b) {
      return distance(a, label.anchor) < distance(b, label.anchor);
    });
    candidates.insert(candidates.end(), grid.begin(), grid.end());

    cv::Rect chosen = clampInto(candidates.front(), area);
    for (const auto& candidate : candidates) {
      const cv::Rect box = clampInto(candidate, area);
      if (!overlapsAny(box, placed)) {
        chosen = box;
        break;
      }
    }
    placed.push_back(chosen);
  }
  return placed;
}

}  // namespace facet::service
