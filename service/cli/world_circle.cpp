#include "service/cli/world_circle.hpp"

#include "algorithms/calibration/plane_circle.hpp"
#include "service/cli/command_line.hpp"

namespace facet::cli {

nlohmann::json worldCircle(const MeasuringPlane& plane, const CircleMeasurement& m) {
  if (const WorldMapping* mapping = plane.mapping()) {
    const auto c = circleInPlane(m, *mapping);
    if (!c)
      throw MeasurementFailure("off_plane",
                               "the circle's rim does not map into the measuring plane");
    return {{"x_mm", c->centreMm.x},          {"y_mm", c->centreMm.y},
            {"diameter_mm", c->diameterMm},   {"rms_mm", c->rmsMm},
            {"roundness_mm", c->roundnessMm}, {"calibration", plane.kind()}};
  }
  const cv::Point2d centre = plane.toPlane(m.centre);
  return {{"x_mm", centre.x},
          {"y_mm", centre.y},
          {"diameter_mm", m.diameter * plane.mmPerPixelAt(m.centre)},
          {"roundness_mm", m.roundness * plane.mmPerPixelAt(m.centre)},
          {"calibration", plane.kind()}};
}

}  // namespace facet::cli
