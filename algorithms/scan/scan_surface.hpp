#pragma once
// The form registration works on (internal to facet_scan): a scan's points with the normal of
// their local line (from neighbours of the same cluster) and a k-d tree (nanoflann) for
// closest-point queries. Built once per scan and match.

#include <cstdint>
#include <memory>
#include <vector>

#include <Eigen/Core>

#include "algorithms/scan/scan.hpp"
#include "algorithms/scan/scan_segmentation.hpp"

namespace facet::scan {

class ScanSurface {
 public:
  // `halfWindow`: neighbours on each side used to fit the local line of a point.
  ScanSurface(ClusteredScan clustered, int halfWindow);
  ~ScanSurface();
  ScanSurface(ScanSurface&&) noexcept;
  ScanSurface& operator=(ScanSurface&&) noexcept;

  [[nodiscard]] const std::vector<Eigen::Vector2d>& points() const { return points_; }
  [[nodiscard]] std::size_t size() const { return points_.size(); }
  // Unit normal of the local line; zero when the point has no line (isolated, or a corner).
  [[nodiscard]] const Eigen::Vector2d& normal(std::size_t i) const { return normals_[i]; }

  struct Closest {
    std::uint32_t index = 0;
    double squaredDistance = 0.0;
  };
  [[nodiscard]] Closest closest(const Eigen::Vector2d& query) const;

 private:
  struct Index;
  std::vector<Eigen::Vector2d> points_;
  std::vector<Eigen::Vector2d> normals_;
  std::unique_ptr<Index> index_;
};

}  // namespace facet::scan
