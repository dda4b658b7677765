// facet caliper: edges and edge pairs along a rotated rectangle (or an arc).
#include <chrono>
#include <iostream>

#include "algorithms/measure/caliper.hpp"
#include "service/cli/command_line.hpp"
#include "service/cli/measuring_options.hpp"

namespace facet::cli {
namespace {

struct CaliperOptions {
  std::string image, rect, arc;
  std::string polarity = "any";
  std::string select = "all";
  bool pairs = false;
  double minAmplitude = CaliperParams{}.minAmplitude;
  bool json = false;
};

nlohmann::json edgeJson(const CaliperEdge& e) {
  return {{"x", e.point.x}, {"y", e.point.y}, {"position", e.position}, {"amplitude", e.amplitude}};
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

  const auto t0 = std::chrono::steady_clock::now();
  const CaliperResult r = measureCaliper(image, path, p);
  const double ms =
      std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
  if (!r.status.ok())
    throw MeasurementFailure(std::string(toString(r.status.cause)),
                             o.image + ": " + r.status.message);

  if (o.json) {
    nlohmann::json edges = nlohmann::json::array(), pairs = nlohmann::json::array();
    for (const CaliperEdge& e : r.edges) edges.push_back(edgeJson(e));
    for (const CaliperPair& pr : r.pairs)
      pairs.push_back({{"x", pr.centre.x},
                       {"y", pr.centre.y},
                       {"position", pr.position},
                       {"width", pr.width},
                       {"first", edgeJson(pr.first)},
                       {"second", edgeJson(pr.second)}});
    // "partial": part of the caliper lay outside the image and only the inside was measured.
    printJson({{"edges", edges}, {"pairs", pairs}, {"partial", r.partial}, {"time_ms", ms}});
    return;
  }
  if (r.partial) std::cout << "note: part of the caliper lies outside the image\n";
  for (const CaliperEdge& e : r.edges)
    std::cout << "edge at (" << e.point.x << ", " << e.point.y << ") px, position " << e.position
              << " px, amplitude " << e.amplitude << "\n";
  for (const CaliperPair& pr : r.pairs)
    std::cout << "pair at (" << pr.centre.x << ", " << pr.centre.y << ") px, width " << pr.width
              << " px\n";
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
  cmd->add_flag("--json", o->json, "Print one JSON object");
  cmd->callback([o] { run(*o); });
}

}  // namespace facet::cli
