#include "algorithms/calibration/plane_blob.hpp"

#include <algorithm>
#include <cmath>
#include <vector>

namespace facet {
namespace {

// The mapping into the plane over an image box, interpolated between exact mappings of nodes
// `kNodeStep` pixels apart: each cell of 2 x 2 node steps is a biquadratic patch through its
// 3 x 3 nodes. Mapping every pixel (an iterative undistortion each) would cost more than the
// blob analysis for large blobs; the patch's error is third order in the node step, below
// 1e-5 mm for the lenses and tilts a station uses (the test compares against every pixel mapped).
constexpr int kNodeStep = 8;

// Lagrange basis through the nodes 0, 1, 2 and its derivative, at t in [0, 2].
struct Basis {
  double l[3], d[3];
  explicit Basis(double t)
      : l{(t - 1) * (t - 2) / 2, -t * (t - 2), t * (t - 1) / 2},
        d{(2 * t - 3) / 2, -(2 * t - 2), (2 * t - 1) / 2} {}
};

}  // namespace

std::optional<PlaneBlob> blobInPlane(const Blob& blob, const WorldMapping& plane) {
  const BlobCoverage& cover = blob.coverage;
  if (cover.share.empty() || cover.share.size() != cover.box.size()) return std::nullopt;
  // Nodes from the box's top-left pixel, an even number of steps covering it.
  const cv::Point2d origin(cover.box.x, cover.box.y);
  const int cellsX = std::max(1, (cover.box.width - 1 + 2 * kNodeStep - 1) / (2 * kNodeStep));
  const int cellsY = std::max(1, (cover.box.height - 1 + 2 * kNodeStep - 1) / (2 * kNodeStep));
  const int nodesX = 2 * cellsX + 1, nodesY = 2 * cellsY + 1;
  std::vector<cv::Point2d> nodes(static_cast<std::size_t>(nodesX * nodesY));
  for (int j = 0; j < nodesY; ++j)
    for (int i = 0; i < nodesX; ++i) {
      const cv::Point2d q = plane.toPlane(origin + cv::Point2d(i, j) * kNodeStep);
      if (!std::isfinite(q.x) || !std::isfinite(q.y)) return std::nullopt;
      nodes[static_cast<std::size_t>(j * nodesX + i)] = q;
    }
  auto node = [&](int i, int j) { return nodes[static_cast<std::size_t>(j * nodesX + i)]; };

  // Sums over the pixels of share x plane area, of it times the plane point, and times its
  // square (about the first node, for conditioning).
  const cv::Point2d ref = nodes.front();
  double m00 = 0, m10 = 0, m01 = 0, m20 = 0, m11 = 0, m02 = 0;
  std::vector<cv::Point2d> rowValue(static_cast<std::size_t>(nodesX)),
      rowSlope(static_cast<std::size_t>(nodesX));
  // Each column's cell and basis, the same on every row.
  std::vector<int> columnCell(static_cast<std::size_t>(cover.box.width));
  std::vector<Basis> columnBasis;
  columnBasis.reserve(static_cast<std::size_t>(cover.box.width));
  for (int c = 0; c < cover.box.width; ++c) {
    const double u = static_cast<double>(c) / kNodeStep;
    const int cx = std::min(static_cast<int>(u / 2), cellsX - 1);
    columnCell[static_cast<std::size_t>(c)] = cx;
    columnBasis.emplace_back(u - 2 * cx);
  }
  for (int r = 0; r < cover.box.height; ++r) {
    const double v = static_cast<double>(r) / kNodeStep;
    const int cy = std::min(static_cast<int>(v / 2), cellsY - 1);
    const Basis by(v - 2 * cy);
    // The patch row at this image row: each node column interpolated down the rows.
    for (int i = 0; i < nodesX; ++i) {
      cv::Point2d value(0, 0), slope(0, 0);
      for (int k = 0; k < 3; ++k) {
        value += by.l[k] * node(i, 2 * cy + k);
        slope += by.d[k] * node(i, 2 * cy + k);
      }
      rowValue[static_cast<std::size_t>(i)] = value;
      rowSlope[static_cast<std::size_t>(i)] = slope / kNodeStep;
    }
    const float* share = cover.share.ptr<float>(r);
    for (int c = 0; c < cover.box.width; ++c) {
      if (share[c] == 0.0F) continue;
      const int cx = columnCell[static_cast<std::size_t>(c)];
      const Basis& bx = columnBasis[static_cast<std::size_t>(c)];
      cv::Point2d q(0, 0), alongX(0, 0), alongY(0, 0);
      for (int k = 0; k < 3; ++k) {
        const auto at = static_cast<std::size_t>(2 * cx + k);
        q += bx.l[k] * rowValue[at];
        alongX += bx.d[k] * rowValue[at];
        alongY += bx.l[k] * rowSlope[at];
      }
      alongX /= kNodeStep;
      // The pixel's area in the plane, mm^2: the patch's Jacobian at its centre.
      const double w = share[c] * std::abs(alongX.x * alongY.y - alongX.y * alongY.x);
      const cv::Point2d d = q - ref;
      m00 += w, m10 += w * d.x, m01 += w * d.y;
      m20 += w * d.x * d.x, m11 += w * d.x * d.y, m02 += w * d.y * d.y;
    }
  }
  if (m00 <= 0) return std::nullopt;
  PlaneBlob b;
  b.areaMm2 = m00;
  const double mx = m10 / m00, my = m01 / m00;
  b.centreMm = ref + cv::Point2d(mx, my);
  const double sxx = m20 / m00 - mx * mx, syy = m02 / m00 - my * my, sxy = m11 / m00 - mx * my;
  const double mean = 0.5 * (sxx + syy);
  const double diff = std::sqrt(0.25 * (sxx - syy) * (sxx - syy) + sxy * sxy);
  // A uniform ellipse of semi-axis r has variance r^2 / 4 along it; scaled to the area, which the
  // blur conserves and spreads the moments (as the image ellipse).
  b.majorRadiusMm = 2.0 * std::sqrt(std::max(0.0, mean + diff));
  b.minorRadiusMm = 2.0 * std::sqrt(std::max(0.0, mean - diff));
  if (const double ellipse = CV_PI * b.majorRadiusMm * b.minorRadiusMm; ellipse > 0) {
    const double k = std::sqrt(m00 / ellipse);
    b.majorRadiusMm *= k, b.minorRadiusMm *= k;
  }
  double a = -0.5 * std::atan2(2 * sxy, sxx - syy) * 180.0 / CV_PI;  // y down: negate
  if (a <= -90) a += 180;
  b.angleDeg = a;
  return b;
}

}  // namespace facet
