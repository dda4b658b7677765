// facet edges: subpixel edge points of one image (Canny + cubic facet model + profile fit).
#include <chrono>
#include <iostream>
#include <optional>
#include <sstream>

#include "algorithms/edges/subpixel_edges.hpp"
#include "algorithms/image/grey_image.hpp"
#include "service/cli/command_line.hpp"

namespace facet::cli {
namespace {

struct EdgesOptions {
  std::string image;
  std::string roi;
  std::optional<double> low, high;
  bool json = false;
};

cv::Rect parseRoi(const std::string& text) {
  std::istringstream in(text);
  int v[4] = {};
  char comma[3] = {};
  if (!(in >> v[0] >> comma[0] >> v[1] >> comma[1] >> v[2] >> comma[2] >> v[3]) ||
      comma[0] != ',' || comma[1] != ',' || comma[2] != ',' || !(in >> std::ws).eof() ||
      v[2] <= 0 || v[3] <= 0)
    throw InputError("--roi must be x,y,w,h in pixels with w, h > 0 (got \"" + text + "\")");
  return {v[0], v[1], v[2], v[3]};
}

void run(const EdgesOptions& o) {
  if (o.low.has_value() != o.high.has_value())
    throw InputError("--low and --high go together (or leave both out for automatic thresholds)");
  if (o.low && (*o.low < 0 || *o.high < *o.low))
    throw InputError("--low/--high must satisfy 0 <= low <= high");
  const cv::Mat image = readGreyImage(o.image);
  EdgeParams params;
  params.low = o.low;
  params.high = o.high;
  if (!o.roi.empty()) {
    params.roi = parseRoi(o.roi);
    if ((params.roi & cv::Rect(0, 0, image.cols, image.rows)).empty())
      throw InputError(o.image + ": --roi " + o.roi + " lies outside the " +
                       std::to_string(image.cols) + "x" + std::to_string(image.rows) + " image");
  }

  const auto t0 = std::chrono::steady_clock::now();
  const EdgeContours edges = detectSubpixelEdges(image, params);
  const double ms =
      std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();

  if (o.json) {
    nlohmann::json points = nlohmann::json::array();
    for (const auto& p : edges.points)
      points.push_back({p.position.x, p.position.y, p.normal.x, p.normal.y, p.magnitude});
    printJson({{"points", std::move(points)},
               {"low", edges.lowThreshold},
               {"high", edges.highThreshold},
               {"time_ms", ms}});
  } else {
    std::cout << edges.points.size() << " edge points in " << ms << " ms (thresholds "
              << edges.lowThreshold << " / " << edges.highThreshold << " grey levels per pixel)\n";
  }
}

}  // namespace

void addEdgesCommand(CLI::App& app) {
  auto* cmd = app.add_subcommand(
      "edges", "Subpixel edge points of an image (position, unit gradient direction, magnitude)");
  auto o = std::make_shared<EdgesOptions>();
  cmd->add_option("--image", o->image, "8- or 16-bit image (colour is converted to grey)")
      ->required();
  cmd->add_option("--roi", o->roi, "Region x,y,w,h in pixels (default: whole image)");
  cmd->add_option("--low", o->low, "Low hysteresis threshold, grey levels per pixel");
  cmd->add_option("--high", o->high, "High hysteresis threshold, grey levels per pixel");
  cmd->add_flag("--json", o->json, "Print one JSON object: {points: [[x,y,nx,ny,magnitude],...]}");
  cmd->callback([o] { run(*o); });
}

}  // namespace facet::cli
