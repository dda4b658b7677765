#pragma once
// The mapping into the measuring plane over a box of the image, for measurements that visit
// every pixel of a region in the plane (a blob's area, a rim's grey values): exact at nodes
// kNodeStep px apart, a biquadratic patch through each cell's 3 x 3 nodes between them.
//
// Why not WorldMapping::toPlane per pixel: each call undistorts iteratively, and a region of
// tens of thousands of pixels would cost more than the measurement. The patch's error is third
// order in the node step, below 1e-5 mm for the lenses and tilts a station uses (plane_blob's
// test compares it with every pixel mapped).

#include <optional>
#include <vector>

#include <opencv2/core.hpp>

#include "algorithms/calibration/world_mapping.hpp"

namespace facet {

// A pixel's place in the plane and the plane's derivatives there along the image's x and y,
// mm and mm per pixel.
struct PlanePixel {
  cv::Point2d mm, alongX, alongY;
};

class PlanePatch {
 public:
  static constexpr int kNodeStep = 8;

  // nullopt when a node's ray misses the plane or the box is empty.
  static std::optional<PlanePatch> over(const WorldMapping& plane, cv::Rect box);

  // One image row of the patch: the node columns interpolated down to that row once, then any
  // pixel of the row from them (a blob visits rows in order).
  class Row {
   public:
    [[nodiscard]] PlanePixel at(int column) const;

   private:
    friend class PlanePatch;
    const PlanePatch* patch_ = nullptr;
    std::vector<cv::Point2d> value_, slope_;
  };
  void load(int row, Row& into) const;
  // Any point of the box (subpixel: the patch is a polynomial between the nodes).
  [[nodiscard]] PlanePixel at(cv::Point2d point) const;

  [[nodiscard]] cv::Rect box() const { return box_; }

 private:
  // Lagrange basis through the nodes 0, 1, 2 and its derivative, at t in [0, 2].
  struct Basis {
    double l[3], d[3];
    explicit Basis(double t);
  };
  PlanePatch(cv::Rect box, int cellsX, int cellsY, std::vector<cv::Point2d> nodes);
  [[nodiscard]] cv::Point2d node(int i, int j) const {
    return nodes_[static_cast<std::size_t>(j * (2 * cellsX_ + 1) + i)];
  }

  cv::Rect box_;
  int cellsX_, cellsY_;
  std::vector<cv::Point2d> nodes_;
  // Each column's cell and basis, the same on every row.
  std::vector<int> columnCell_;
  std::vector<Basis> columnBasis_;
};

}  // namespace facet
