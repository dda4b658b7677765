// facet line: position, angle and straightness of a straight edge in a rotated rectangle.
#include <chrono>
#include <iostream>

#include "algorithms/measure/line_measure.hpp"
#include "service/cli/command_line.hpp"
#include "service/cli/measuring_options.hpp"

namespace facet::cli {
namespace {

struct LineOptions {
  std::string image, rect;
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

  const auto t0 = std::chrono::steady_clock::now();
  const LineMeasurement m = measureLine(image, rect, p);
  const double ms =
      std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
  if (!m.status.ok())
    throw MeasurementFailure(std::string(toString(m.status.cause)),
                             o.image + ": " + m.status.message);

  if (o.json) {
    printJson(
        {{"line",
          {{"x1", m.p1.x}, {"y1", m.p1.y}, {"x2", m.p2.x}, {"y2", m.p2.y}, {"angle", m.angle}}},
         {"rms", m.rms},
         {"straightness", m.straightness},
         {"points", m.points},
         {"partial", m.partial},
         {"time_ms", ms}});
    return;
  }
  if (m.partial) std::cout << "note: part of the rectangle lies outside the image\n";
  std::cout << "line from (" << m.p1.x << ", " << m.p1.y << ") to (" << m.p2.x << ", " << m.p2.y
            << ") px, angle " << m.angle << " deg\nstraightness " << m.straightness << " px, rms "
            << m.rms << " px, " << m.points << " points, " << ms << " ms\n";
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
  cmd->add_flag("--json", o->json, "Print one JSON object");
  cmd->callback([o] { run(*o); });
}

}  // namespace facet::cli
