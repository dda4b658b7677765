// facet caliper: edges and edge pairs along a rotated rectangle (or an arc).
#include <chrono>
#include <iostream>
#include <optional>

#include "algorithms/measure/caliper.hpp"
#include "service/cli/command_line.hpp"
#include "service/cli/measuring_options.hpp"
#include "service/cli/measuring_plane.hpp"

namespace facet::cli {
namespace {

struct CaliperOptions {
  std::string image, rect, arc;
  std::string calibration;  // calibration file: adds positions and widths in the plane, mm
  std::string polarity = "any";
  std::string select = "all";
  bool pairs = false;
  double minAmplitude = CaliperParams{}.minAmplitude;
  bool json = false;
};

// `plane`: also the edge's place and position in the measuring plane, mm.
nlohmann::json edgeJson(const CaliperEdge& e, const MeasuringPath& path,
                        const MeasuringPlane* plane) {
  nlohmann::json j{{"x", e.point.x},
                   {"y", e.point.y},
                   {"position", e.position},
                   {"amplitude", e.amplitude},
                   {"clipped", e.clipped}};
  if (plane) {
    const cv::Point2d q = plane->toPlane(e.point);
    j["x_mm"] = q.x;
    j["y_mm"] = q.y;
    j["position_mm"] = plane->span(path, 0.0, e.position);
  }
  return j;
}

void run(const CaliperOptions& o) {
  if (o.rect.empty() == o.arc.empty()) throw InputError("give exactly one of --rect and --arc");
  if (!(o.minAmplitude > 0)) throw InputError("--min-amplitude must be positive");
  CaliperParams p;
  p.polarity = parseEdgePolarity(o.polarity);
  p.select = parseEdgeSelect(o.select);
  p.pairs = o.pairs;
  p.minAmplitude = o.minAmplitude;
  const MeasuringPath path = o.rect.empty() ? MeasuringPath(parseMeasuringArc(o.arc, "--arc"))
                                            : MeasuringPath(parseMeasuringRect(o.rect, "--rect"));
  const cv::Mat image = readGreyImage(o.image);
  std::optional<MeasuringPlane> plane;
  if (!o.calibration.empty()) plane.emplace(o.calibration, image.size());
  const MeasuringPlane* inPlane = plane ? &*plane : nullptr;

  const auto t0 = std::chrono::steady_clock::now();
  const CaliperResult r = measureCaliper(image, path, p);
  const double ms =
      std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
  if (!r.status.ok())
    throw MeasurementFailure(std::string(toString(r.status.cause)),
                             o.image + ": " + r.status.message);

  if (o.json) {
    nlohmann::json edges = nlohmann::json::array(), pairs = nlohmann::json::array();
    for (const CaliperEdge& e : r.edges) edges.push_back(edgeJson(e, path, inPlane));
    for (const CaliperPair& pr : r.pairs) {
      nlohmann::json j{{"x", pr.centre.x},
                       {"y", pr.centre.y},
                       {"position", pr.position},
                       {"width", pr.width},
                       {"first", edgeJson(pr.first, path, inPlane)},
                       {"second", edgeJson(pr.second, path, inPlane)}};
      if (plane) {
        // The pair's middle in the plane: halfway between its edges there.
        const double mid = plane->midpoint(path, pr.first.position, pr.second.position);
        const cv::Point2d q = plane->toPlane(path.at(mid, 0.0));
        j["x_mm"] = q.x;
        j["y_mm"] = q.y;
        j["position_mm"] = plane->span(path, 0.0, mid);
        j["width_mm"] = plane->span(path, pr.first.position, pr.second.position);
      }
      pairs.push_back(j);
    }
    // "partial": part of the caliper lay outside the image and only the inside was measured.
    nlohmann::json out{{"edges", edges}, {"pairs", pairs}, {"partial", r.partial}, {"time_ms", ms}};
    if (plane) out["calibration"] = plane->kind();
    printJson(out);
    return;
  }
  if (r.partial) std::cout << "note: part of the caliper lies outside the image\n";
  for (const CaliperEdge& e : r.edges) {
    std::cout << "edge at (" << e.point.x << ", " << e.point.y << ") px, position " << e.position
              << " px, amplitude " << e.amplitude;
    if (plane) std::cout << "; position " << plane->span(path, 0.0, e.position) << " mm";
    if (e.clipped)
      std::cout << " (the sensor clipped the grey values beside it: up to a pixel towards the "
                   "unclipped side; lower the exposure)";
    std::cout << "\n";
  }
  for (const CaliperPair& pr : r.pairs) {
    std::cout << "pair at (" << pr.centre.x << ", " << pr.centre.y << ") px, width " << pr.width
              << " px";
    if (plane)
      std::cout << "; width " << plane->span(path, pr.first.position, pr.second.position) << " mm";
    std::cout << "\n";
  }
  if (plane) std::cout << "lengths in the measuring plane: " << plane->kind() << "\n";
  std::cout << ms << " ms\n";
}

}  // namespace

void addCaliperCommand(CLI::App& app) {
  auto* cmd = app.add_subcommand(
      "caliper", "Subpixel edges and edge pairs (widths) along a rotated rectangle or an arc");
  auto o = std::make_shared<CaliperOptions>();
  cmd->add_option("--image", o->image, "8/16-bit image file")->required();
  cmd->add_option("--rect", o->rect,
                  "cx,cy,length,width,angle: the measuring axis runs along angle (degrees, "
                  "counter-clockwise on screen), positions are signed from the centre");
  cmd->add_option("--arc", o->arc,
                  "cx,cy,radius,start,extent,width: measure along an arc instead (degrees)");
  cmd->add_option("--polarity", o->polarity,
                  "any (default), rising (dark to light along the axis) or falling");
  cmd->add_option("--select", o->select, "all (default), first, last or strongest");
  cmd->add_flag("--pairs", o->pairs,
                "also report pairs of neighbouring edges of opposite polarity (widths); "
                "--polarity then gives the first edge's");
  cmd->add_option("--min-amplitude", o->minAmplitude,
                  "smallest grey step of an edge, 8-bit grey levels (default 20)");
  cmd->add_option("--calibration", o->calibration,
                  "calibration file (facet calibrate): adds places, positions and widths in the "
                  "measuring plane, mm");
  cmd->add_flag("--json", o->json, "Print one JSON object");
  cmd->callback([o] { run(*o); });
}

}  // namespace facet::cli
