#include "algorithms/calibration/plane_patch.hpp"

#include <algorithm>
#include <cmath>
#include <utility>

namespace facet {

PlanePatch::Basis::Basis(double t)
    : l{(t - 1) * (t - 2) / 2, -t * (t - 2), t * (t - 1) / 2},
      d{(2 * t - 3) / 2, -(2 * t - 2), (2 * t - 1) / 2} {}

std::optional<PlanePatch> PlanePatch::over(const WorldMapping& plane, cv::Rect box) {
  if (box.width <= 0 || box.height <= 0) return std::nullopt;
  // Nodes from the box's top-left pixel, an even number of steps covering it.
  const cv::Point2d origin(box.x, box.y);
  const int cellsX = std::max(1, (box.width - 1 + 2 * kNodeStep - 1) / (2 * kNodeStep));
  const int cellsY = std::max(1, (box.height - 1 + 2 * kNodeStep - 1) / (2 * kNodeStep));
  const int nodesX = 2 * cellsX + 1, nodesY = 2 * cellsY + 1;
  std::vector<cv::Point2d> nodes(static_cast<std::size_t>(nodesX * nodesY));
  for (int j = 0; j < nodesY; ++j)
    for (int i = 0; i < nodesX; ++i) {
      const cv::Point2d q = plane.toPlane(origin + cv::Point2d(i, j) * kNodeStep);
      if (!std::isfinite(q.x) || !std::isfinite(q.y)) return std::nullopt;
      nodes[static_cast<std::size_t>(j * nodesX + i)] = q;
    }
  return PlanePatch(box, cellsX, cellsY, std::move(nodes));
}

PlanePatch::PlanePatch(cv::Rect box, int cellsX, int cellsY, std::vector<cv::Point2d> nodes)
    : box_(box), cellsX_(cellsX), cellsY_(cellsY), nodes_(std::move(nodes)) {
  columnCell_.reserve(static_cast<std::size_t>(box.width));
  columnBasis_.reserve(static_cast<std::size_t>(box.width));
  for (int c = 0; c < box.width; ++c) {
    const double u = static_cast<double>(c) / kNodeStep;
    const int cx = std::min(static_cast<int>(u / 2), cellsX_ - 1);
    columnCell_.push_back(cx);
    columnBasis_.emplace_back(u - 2 * cx);
  }
}

void PlanePatch::load(int row, Row& into) const {
  const int r = row - box_.y;
  const double v = static_cast<double>(r) / kNodeStep;
  const int cy = std::clamp(static_cast<int>(std::floor(v / 2)), 0, cellsY_ - 1);
  const Basis by(v - 2 * cy);
  const int nodesX = 2 * cellsX_ + 1;
  into.patch_ = this;
  into.value_.assign(static_cast<std::size_t>(nodesX), {0, 0});
  into.slope_.assign(static_cast<std::size_t>(nodesX), {0, 0});
  for (int i = 0; i < nodesX; ++i) {
    cv::Point2d value(0, 0), slope(0, 0);
    for (int k = 0; k < 3; ++k) {
      value += by.l[k] * node(i, 2 * cy + k);
      slope += by.d[k] * node(i, 2 * cy + k);
    }
    into.value_[static_cast<std::size_t>(i)] = value;
    into.slope_[static_cast<std::size_t>(i)] = slope / kNodeStep;
  }
}

PlanePixel PlanePatch::Row::at(int column) const {
  const auto c = static_cast<std::size_t>(column - patch_->box_.x);
  const int cx = patch_->columnCell_[c];
  const Basis& bx = patch_->columnBasis_[c];
  PlanePixel p{{0, 0}, {0, 0}, {0, 0}};
  for (int k = 0; k < 3; ++k) {
    const auto at = static_cast<std::size_t>(2 * cx + k);
    p.mm += bx.l[k] * value_[at];
    p.alongX += bx.d[k] * value_[at];
    p.alongY += bx.l[k] * slope_[at];
  }
  p.alongX /= kNodeStep;
  return p;
}

PlanePixel PlanePatch::at(cv::Point2d point) const {
  const double u = (point.x - box_.x) / kNodeStep, v = (point.y - box_.y) / kNodeStep;
  const int cx = std::clamp(static_cast<int>(std::floor(u / 2)), 0, cellsX_ - 1);
  const int cy = std::clamp(static_cast<int>(std::floor(v / 2)), 0, cellsY_ - 1);
  const Basis bx(u - 2 * cx), by(v - 2 * cy);
  PlanePixel p{{0, 0}, {0, 0}, {0, 0}};
  for (int j = 0; j < 3; ++j)
    for (int k = 0; k < 3; ++k) {
      const cv::Point2d n = node(2 * cx + k, 2 * cy + j);
      p.mm += by.l[j] * bx.l[k] * n;
      p.alongX += by.l[j] * bx.d[k] * n;
      p.alongY += by.d[j] * bx.l[k] * n;
    }
  p.alongX /= kNodeStep;
  p.alongY /= kNodeStep;
  return p;
}

}  // namespace facet
