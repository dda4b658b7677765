// facet blob: threshold, connected components and their features in a region.
#include <chrono>
#include <cmath>
#include <iostream>
#include <limits>
#include <optional>

#include "algorithms/measure/blob_analysis.hpp"
#include "service/cli/command_line.hpp"
#include "service/cli/measuring_options.hpp"
#include "service/cli/measuring_plane.hpp"

namespace facet::cli {
namespace {

struct BlobOptions {
  std::string image, roi;
  std::string threshold = "auto";
  std::string polarity = "light";
  double minArea = 0;
  double maxArea = std::numeric_limits<double>::infinity();
  double minRoundness = 0;
  bool pixelArea = false;
  std::string calibration;  // calibration file: adds centroids and areas in the plane, mm
  bool json = false;
};

// "auto" (Otsu in the region), a grey level, or "median:D" (D grey levels from the region's
// median towards the blobs' side).
void parseThreshold(const std::string& text, BlobParams& p) {
  const std::string error =
      "--threshold must be auto, a grey level 0-255 or median:D (got \"" + text + "\")";
  auto number = [&](const std::string& s) {
    std::size_t used = 0;
    double v = 0;
    try {
      v = std::stod(s, &used);
    } catch (const std::exception&) {
      throw InputError(error);
    }
    if (used != s.size() || !std::isfinite(v)) throw InputError(error);
    return v;
  };
  if (text == "auto") {
    p.mode = BlobThreshold::Otsu;
  } else if (text.rfind("median:", 0) == 0) {
    p.mode = BlobThreshold::RelativeToMedian;
    p.threshold = number(text.substr(7));
    if (p.threshold < 0) throw InputError(error);
  } else {
    p.mode = BlobThreshold::Fixed;
    p.threshold = number(text);
    if (p.threshold < 0 || p.threshold > 255) throw InputError(error);
  }
}

void run(const BlobOptions& o) {
  BlobParams p;
  parseThreshold(o.threshold, p);
  if (o.polarity == "light")
    p.polarity = BlobPolarity::Light;
  else if (o.polarity == "dark")
    p.polarity = BlobPolarity::Dark;
  else
    throw InputError("--polarity must be light or dark (got \"" + o.polarity + "\")");
  if (!(o.minArea >= 0) || !(o.maxArea > o.minArea))
    throw InputError("--min-area must be >= 0 and below --max-area");
  p.minArea = o.minArea;
  p.maxArea = o.maxArea;
  if (!(o.minRoundness >= 0 && o.minRoundness <= 1))
    throw InputError("--min-roundness must be between 0 and 1");
  p.minRoundness = o.minRoundness;
  p.greyArea = !o.pixelArea;
  if (!o.roi.empty()) {
    p.roi = parseRegion(o.roi, "--roi");
    if (p.roi.width <= 0 || p.roi.height <= 0)
      throw MeasurementFailure("zero_size", o.image + ": the --roi region has zero size");
  }
  const cv::Mat image = readGreyImage(o.image);
  std::optional<MeasuringPlane> plane;
  if (!o.calibration.empty()) plane.emplace(o.calibration, image.size());
  p.keepCoverage = plane && plane->mapping();

  const auto t0 = std::chrono::steady_clock::now();
  const BlobResult r = analyseBlobs(image, p);
  const double ms =
      std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
  if (!r.status.ok())
    throw MeasurementFailure(std::string(toString(r.status.cause)),
                             o.image + ": " + r.status.message);

  if (o.json) {
    nlohmann::json blobs = nlohmann::json::array();
    for (const Blob& b : r.blobs) {
      nlohmann::json j{
          {"x", b.centroid.x},
          {"y", b.centroid.y},
          {"area", b.area},
          {"pixels", b.pixels},
          {"bbox", {b.bbox.x, b.bbox.y, b.bbox.width, b.bbox.height}},
          {"ellipse",
           {{"major_radius", b.majorRadius}, {"minor_radius", b.minorRadius}, {"angle", b.angle}}},
          {"touches_border", b.touchesBorder}};
      if (plane) {
        const PlaneBlob q = plane->blob(b);
        j["x_mm"] = q.centreMm.x;
        j["y_mm"] = q.centreMm.y;
        j["area_mm2"] = q.areaMm2;
        j["ellipse_mm"] = {{"major_radius", q.majorRadiusMm},
                           {"minor_radius", q.minorRadiusMm},
                           {"angle", q.angleDeg}};
      }
      blobs.push_back(j);
    }
    nlohmann::json out{
        {"blobs", blobs}, {"threshold", r.threshold}, {"partial", r.partial}, {"time_ms", ms}};
    if (plane) out["calibration"] = plane->kind();
    printJson(out);
    return;
  }
  if (r.partial) std::cout << "note: the region was clipped to the image\n";
  std::cout << r.blobs.size() << " blobs (threshold " << r.threshold << ")\n";
  for (const Blob& b : r.blobs) {
    std::cout << "  (" << b.centroid.x << ", " << b.centroid.y << ") area " << b.area
              << " px^2, bbox " << b.bbox.x << "," << b.bbox.y << "," << b.bbox.width << ","
              << b.bbox.height;
    if (plane) {
      const PlaneBlob q = plane->blob(b);
      std::cout << "; (" << q.centreMm.x << ", " << q.centreMm.y << ") mm, area " << q.areaMm2
                << " mm^2";
    }
    std::cout << "\n";
  }
  if (plane) std::cout << "in the measuring plane: " << plane->kind() << "\n";
  std::cout << ms << " ms\n";
}

}  // namespace

void addBlobCommand(CLI::App& app) {
  auto* cmd = app.add_subcommand(
      "blob", "Threshold a region and measure its connected components (count, area, centroid)");
  auto o = std::make_shared<BlobOptions>();
  cmd->add_option("--image", o->image, "8/16-bit image file")->required();
  cmd->add_option("--roi", o->roi, "x,y,w,h region in pixels (default: the whole image)");
  cmd->add_option("--threshold", o->threshold,
                  "auto (Otsu in the region, default), a grey level 0-255, or median:D (D grey "
                  "levels from the region's median towards the blobs)");
  cmd->add_option("--polarity", o->polarity, "light (default) or dark blobs");
  cmd->add_option("--min-area", o->minArea, "smallest blob area in pixels^2 (default 0)");
  cmd->add_option("--max-area", o->maxArea, "largest blob area in pixels^2 (default none)");
  cmd->add_option("--min-roundness", o->minRoundness,
                  "smallest minor / major axis ratio of a blob's ellipse kept, 0..1 (default 0)");
  cmd->add_flag("--pixel-area", o->pixelArea,
                "areas as thresholded pixel counts instead of the subpixel grey-value area");
  cmd->add_option("--calibration", o->calibration,
                  "calibration file (facet calibrate): adds centroids and areas in the measuring "
                  "plane, mm");
  cmd->add_flag("--json", o->json, "Print one JSON object");
  cmd->callback([o] { run(*o); });
}

}  // namespace facet::cli
