#include "algorithms/calibration/plane_blob.hpp"

#include <algorithm>
#include <cmath>
#include <vector>

#include "algorithms/calibration/plane_patch.hpp"

namespace facet {

std::optional<PlaneBlob> blobInPlane(const Blob& blob, const WorldMapping& plane) {
  const BlobCoverage& cover = blob.coverage;
  if (cover.share.empty() || cover.share.size() != cover.box.size()) return std::nullopt;
  const auto patch = PlanePatch::over(plane, cover.box);
  if (!patch) return std::nullopt;

  // Sums over the pixels of share x plane area, of it times the plane point, and times its
  // square (about the first node, for conditioning).
  const cv::Point2d ref = plane.toPlane(cv::Point2d(cover.box.x, cover.box.y));
  double m00 = 0, m10 = 0, m01 = 0, m20 = 0, m11 = 0, m02 = 0;
  PlanePatch::Row row;
  for (int r = 0; r < cover.box.height; ++r) {
    patch->load(cover.box.y + r, row);
    const float* share = cover.share.ptr<float>(r);
    for (int c = 0; c < cover.box.width; ++c) {
      if (share[c] == 0.0F) continue;
      const PlanePixel p = row.at(cover.box.x + c);
      // The pixel's area in the plane, mm^2: the patch's Jacobian at its centre.
      const double w = share[c] * std::abs(p.alongX.x * p.alongY.y - p.alongX.y * p.alongY.x);
      const cv::Point2d d = p.mm - ref;
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
