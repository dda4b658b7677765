#include "service/engine/steps/pose_offset.hpp"

#include <cmath>

namespace facet::service {

bool setPoseOffset(StepResult& r, const std::optional<WorldMapping>& plane, cv::Point2d nominal,
                   cv::Point2d found, double angleDeg) {
  if (!plane) {
    r.values["x"] = found.x - nominal.x;
    r.values["y"] = found.y - nominal.y;
    r.values["angle"] = angleDeg;
    return true;
  }
  const double a = angleDeg * CV_PI / 180.0;
  // The x direction of the nominal part and of the found one, a pixel long, in the plane.
  const cv::Point2d n0 = plane->toPlane(nominal), n1 = plane->toPlane(nominal + cv::Point2d(1, 0));
  const cv::Point2d f0 = plane->toPlane(found);
  const cv::Point2d f1 = plane->toPlane(found + cv::Point2d(std::cos(a), -std::sin(a)));
  const cv::Point2d dn = n1 - n0, df = f1 - f0;
  if (!std::isfinite(dn.x + dn.y + df.x + df.y)) return false;
  r.lengthsInMm = true;
  r.values["x"] = f0.x - n0.x;
  r.values["y"] = f0.y - n0.y;
  // The plane's y runs down the image as pixels do: counter-clockwise on screen is negative.
  r.values["angle"] = -std::atan2(dn.x * df.y - dn.y * df.x, dn.dot(df)) * 180.0 / CV_PI;
  return true;
}

}  // namespace facet::service
