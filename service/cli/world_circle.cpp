#include "service/cli/world_circle.hpp"

#include "algorithms/calibration/plane_circle.hpp"
#include "service/cli/command_line.hpp"

namespace facet::cli {

nlohmann::json worldCircle(const MeasuringPlane& plane, const cv::Mat& image,
                           const CircleMeasurement& m, const CircleMeasureParams& params,
                           std::string& refusal) {
  if (const WorldMapping* mapping = plane.mapping()) {
    const PlaneCircleVerdict verdict = measureCircleInPlane(image, m, params, *mapping);
    refusal = verdict.refusal;
    if (!verdict.circle) {
      if (!m.status.ok()) return nullptr;
      if (!verdict.refusal.empty()) throw MeasurementFailure("fit_too_poor", verdict.refusal);
      throw MeasurementFailure("off_plane",
                               "the circle's rim does not map into the measuring plane");
    }
    const PlaneCircle* c = &*verdict.circle;
    const bool judged = verdict.judgedInPlane;
    return {{"x_mm", c->centreMm.x},          {"y_mm", c->centreMm.y},
            {"diameter_mm", c->diameterMm},   {"rms_mm", c->rmsMm},
            {"roundness_mm", c->roundnessMm}, {"coverage_deg", c->coverageDeg},
            {"grey_refined", c->greyRefined}, {"judged_in_plane", judged},
            {"calibration", plane.kind()}};
  }
  if (!m.status.ok()) return nullptr;
  const cv::Point2d centre = plane.toPlane(m.centre);
  return {{"x_mm", centre.x},
          {"y_mm", centre.y},
          {"diameter_mm", m.diameter * plane.mmPerPixelAt(m.centre)},
          {"roundness_mm", m.roundness * plane.mmPerPixelAt(m.centre)},
          {"calibration", plane.kind()}};
}

}  // namespace facet::cli
