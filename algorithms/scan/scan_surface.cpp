#include "algorithms/scan/scan_surface.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

#include <Eigen/Eigenvalues>
#include <nanoflann.hpp>

namespace facet::scan {
namespace {

// nanoflann reads points through this view; it points at the vector's heap buffer, which
// stays put when the owning ScanSurface moves.
struct PointView {
  const Eigen::Vector2d* data = nullptr;
  std::size_t count = 0;
  [[nodiscard]] std::size_t kdtree_get_point_count() const { return count; }
  [[nodiscard]] double kdtree_get_pt(std::size_t i, std::size_t dim) const { return data[i][dim]; }
  template <class Box>
  bool kdtree_get_bbox(Box&) const {
    return false;
  }
};

// Unit normal of the line through the points [first, last], or zero when they are not on a
// line: fewer than two points, or spread as much across as along (a corner or a blob).
Eigen::Vector2d lineNormal(const std::vector<Eigen::Vector2d>& points, int first, int last) {
  const int n = last - first + 1;
  if (n < 2) return Eigen::Vector2d::Zero();
  Eigen::Vector2d mean = Eigen::Vector2d::Zero();
  for (int i = first; i <= last; ++i) mean += points[i];
  mean /= n;
  Eigen::Matrix2d scatter = Eigen::Matrix2d::Zero();
  for (int i = first; i <= last; ++i) {
    const Eigen::Vector2d d = points[i] - mean;
    scatter += d * d.transpose();
  }
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix2d> eig(scatter);
  const Eigen::Vector2d values = eig.eigenvalues();  // ascending
  if (values(1) <= 0.0 || values(0) > 0.1 * values(1)) return Eigen::Vector2d::Zero();
  return eig.eigenvectors().col(0).normalized();
}

}  // namespace

struct ScanSurface::Index {
  using Tree = nanoflann::KDTreeSingleIndexAdaptor<nanoflann::L2_Simple_Adaptor<double, PointView>,
                                                   PointView, 2, std::uint32_t>;
  explicit Index(PointView v)
      : view(v), tree(2, view, nanoflann::KDTreeSingleIndexAdaptorParams(8)) {}
  PointView view;
  Tree tree;
};

ScanSurface::ScanSurface(ClusteredScan clustered, int halfWindow)
    : points_(std::move(clustered.scan.points)) {
  normals_.assign(points_.size(), Eigen::Vector2d::Zero());
  for (const Cluster& c : clustered.clusters) {
    for (int i = c.begin; i < c.end; ++i) {
      normals_[i] = lineNormal(points_, std::max(c.begin, i - halfWindow),
                               std::min(c.end - 1, i + halfWindow));
    }
  }
  if (!points_.empty()) index_ = std::make_unique<Index>(PointView{points_.data(), points_.size()});
}

ScanSurface::~ScanSurface() = default;
ScanSurface::ScanSurface(ScanSurface&&) noexcept = default;
ScanSurface& ScanSurface::operator=(ScanSurface&&) noexcept = default;

ScanSurface::Closest ScanSurface::closest(const Eigen::Vector2d& query) const {
  Closest found{0, std::numeric_limits<double>::infinity()};
  if (!index_) return found;
  nanoflann::KNNResultSet<double, std::uint32_t> result(1);
  result.init(&found.index, &found.squaredDistance);
  index_->tree.findNeighbors(result, query.data(), nanoflann::SearchParams(0));
  return found;
}

}  // namespace facet::scan
