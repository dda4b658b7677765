// facet line: position, angle and straightness of a straight edge in a rotated rectangle.
#include <chrono>
#include <cmath>
#include <iostream>
#include <optional>

#include "algorithms/measure/line_measure.hpp"
#include "service/cli/command_line.hpp"
#include "service/cli/measuring_options.hpp"
#include "service/cli/measuring_plane.hpp"

namespace facet::cli {
namespace {

struct LineOptions {
  std::string image, rect;
  std::string calibration;  // calibration file: adds the line in the plane, mm
  std::string polarity = "any";
  double minAmplitude = LineMeasureParams{}.minAmplitude;
  bool json = false;
};

void run(const LineOptions& o) {
  if (!(o.minAmplitude > 0)) throw InputError("--min-amplitude must be positive");
  LineMeasureParams p;
  p.polarity = parseEdgePolarity(o.polarity);
  p.minAmplitude = o.minAmplitude;
  const MeasuringRect rect = parseMeasuringRect(o.rect, "--rect");
  const cv::Mat image = readGreyImage(o.image);
  std::optional<MeasuringPlane> plane;
  if (!o.calibration.empty()) plane.emplace(o.calibration, image.size());

  const auto t0 = std::chrono::steady_clock::now();
  const LineMeasurement m = measureLine(image, rect, p);
  const double ms =
      std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
  if (!m.status.ok())
    throw MeasurementFailure(std::string(toString(m.status.cause)),
                             o.image + ": " + m.status.message);

  // In the plane: the segment's ends, its angle in the plane's axes (counter-clockwise as on
  // screen: the plane's y runs down the image as pixels do), its deviations.
  std::optional<LineInPlane> seen;
  if (plane) seen = plane->line(rect, m);
  const auto planeAngle = [&] {
    const cv::Point2d d = seen->p2 - seen->p1;
    return std::atan2(-d.y, d.x) * 180.0 / CV_PI;
  };
  if (o.json) {
    nlohmann::json out{
        {"line",
         {{"x1", m.p1.x}, {"y1", m.p1.y}, {"x2", m.p2.x}, {"y2", m.p2.y}, {"angle", m.angle}}},
        {"rms", m.rms},
        {"straightness", m.straightness},
        {"points", m.points},
        {"clipped_points", m.clippedPoints},
        {"partial", m.partial},
        {"time_ms", ms}};
    if (seen) {
      out["line_mm"] = {{"x1", seen->p1.x},
                        {"y1", seen->p1.y},
                        {"x2", seen->p2.x},
                        {"y2", seen->p2.y},
                        {"angle", planeAngle()}};
      out["rms_mm"] = seen->rms;
      out["straightness_mm"] = seen->straightness;
      out["calibration"] = plane->kind();
    }
    printJson(out);
    return;
  }
  if (m.partial) std::cout << "note: part of the rectangle lies outside the image\n";
  if (m.clippedPoints > 0)
    std::cout << "note: " << m.clippedPoints
              << " points lie beside grey values the sensor clipped (up to a pixel towards the "
                 "unclipped side); lower the exposure\n";
  std::cout << "line from (" << m.p1.x << ", " << m.p1.y << ") to (" << m.p2.x << ", " << m.p2.y
            << ") px, angle " << m.angle << " deg\nstraightness " << m.straightness << " px, rms "
            << m.rms << " px, " << m.points << " points, " << ms << " ms\n";
  if (seen)
    std::cout << "in the plane: from (" << seen->p1.x << ", " << seen->p1.y << ") to ("
              << seen->p2.x << ", " << seen->p2.y << ") mm, angle " << planeAngle()
              << " deg, straightness " << seen->straightness << " mm, rms " << seen->rms << " mm ("
              << plane->kind() << ")\n";
}

}  // namespace

void addLineCommand(CLI::App& app) {
  auto* cmd = app.add_subcommand(
      "line",
      "Fit a straight edge in a rotated rectangle laid along it: segment, angle, "
      "straightness");
  auto o = std::make_shared<LineOptions>();
  cmd->add_option("--image", o->image, "8/16-bit image file")->required();
  cmd->add_option("--rect", o->rect,
                  "cx,cy,length,width,angle: the rectangle's axis along the expected line; the "
                  "edge is searched across its width")
      ->required();
  cmd->add_option("--polarity", o->polarity,
                  "any (default), rising (dark to light across, i.e. towards (sin a, cos a)) or "
                  "falling");
  cmd->add_option("--min-amplitude", o->minAmplitude,
                  "smallest grey step of an edge point, 8-bit grey levels (default 20)");
  cmd->add_option("--calibration", o->calibration,
                  "calibration file (facet calibrate): adds the line in the measuring plane, mm");
  cmd->add_flag("--json", o->json, "Print one JSON object");
  cmd->callback([o] { run(*o); });
}

}  // namespace facet::cli
