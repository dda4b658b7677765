#include "service/engine/steps/blob_step.hpp"

#include <algorithm>
#include <cmath>

#include "algorithms/calibration/plane_blob.hpp"
#include "config/recipe_format.hpp"
#include "service/engine/steps/placed_rect.hpp"
#include "service/engine/steps/pose_fields.hpp"

namespace facet::service {

using config::Quantity;

BlobStep::BlobStep() : TableStep({.point = true}) {
  addRelativeTo(fields_);
  addMeasuringRect(fields_, "Length of the searched rectangle along its axis, pixels.",
                   "Width of the searched rectangle across its axis, pixels.");
  fields_.choice("polarity", &BlobStepParams::polarity,
                 {{"dark", BlobPolarity::Dark}, {"light", BlobPolarity::Light}},
                 "Blobs darker (holes) or lighter than their surroundings.");
  fields_.choice("threshold", &BlobStepParams::threshold,
                 {{"otsu", BlobThreshold::Otsu},
                  {"fixed", BlobThreshold::Fixed},
                  {"relative_to_median", BlobThreshold::RelativeToMedian}},
                 "otsu (automatic, in the region), fixed (the grey level `level`) or "
                 "relative_to_median (`level` grey levels from the region's median).");
  fields_.number("level", &BlobStepParams::level,
                 "Grey level (8-bit scale) for threshold fixed and relative_to_median.",
                 {.minimum = 0.0, .maximum = 255.0});
  fields_.number("min_area", &BlobStepParams::minArea,
                 "Smallest blob kept, pixels^2 of the live image.", {.minimum = 0.0});
  fields_.number("max_area", &BlobStepParams::maxArea,
                 "Largest blob kept, pixels^2 of the live image.",
                 {.minimum = 0.0, .exclusiveMinimum = true});
  fields_.number("min_roundness", &BlobStepParams::minRoundness,
                 "Smallest minor / major axis ratio of a blob's ellipse kept, 0..1.",
                 {.minimum = 0.0, .maximum = 1.0});
  fields_.add({.name = "required",
               .type = config::FieldType::Boolean,
               .description = "Whether a region without a blob fails the step with that cause "
                              "(false: count and presence are 0, for absence checks).",
               .defaultValue = true},
              [](BlobStepParams& b, const YAML::Node& n, config::StepReading&) {
                if (const auto v = config::readBoolean(n)) b.required = *v;
              });
  checks_ = {
      "blob checks",
      "",
      {config::checkField("count", Quantity::Count, "Number of blobs found.", 0.0),
       config::checkField("presence", Quantity::Count, "1 when a blob is found, else 0.", 0.0),
       config::checkField("area", Quantity::Area, "Area of the largest blob.", 0.0)}};
  describe("blob", "Dark or light blobs in a rectangle: presence, count, area.");
}

void BlobStep::crossCheck(const BlobStepParams& b, config::StepReading& in) const {
  if (b.maxArea < b.minArea)
    in.error(in["max_area"] ? in["max_area"] : in["min_area"], "'max_area' is below 'min_area'");
}

StepResult BlobStep::run(const config::Step& step, StepContext& part) const {
  const auto& b = step.as<BlobStepParams>();
  const MeasuringRect rect =
      placeRect(part.frameOf(b.relativeTo), b.centre, b.length, b.width, b.angle);
  const std::vector<cv::Point2d> corners = rectCorners(rect);
  part.overlay.polygon(corners, true, true);
  // The blobs are labelled in the box around the rectangle and kept when their centre lies in it.
  double x0 = corners[0].x, x1 = x0, y0 = corners[0].y, y1 = y0;
  for (const cv::Point2d& c : corners) {
    x0 = std::min(x0, c.x), x1 = std::max(x1, c.x);
    y0 = std::min(y0, c.y), y1 = std::max(y1, c.y);
  }
  BlobParams p;
  p.roi = cv::Rect(cv::Point(int(std::floor(x0 + 0.5)), int(std::floor(y0 + 0.5))),
                   cv::Point(int(std::floor(x1 + 0.5)) + 1, int(std::floor(y1 + 0.5)) + 1));
  if (p.roi.empty()) return StepResult::failed("blobs not searched: the rectangle has zero size");
  p.mode = b.threshold;
  p.threshold = b.level;
  p.polarity = b.polarity;
  p.minArea = b.minArea;
  p.maxArea = b.maxArea;
  p.minRoundness = b.minRoundness;
  // With a lens model and a measuring plane the largest blob is measured there (plane_blob.hpp).
  const auto plane = part.calibration.worldMapping();
  p.keepCoverage = plane.has_value();
  const BlobResult m = analyseBlobs(part.grey, p);
  const bool none =
      m.status.cause == MeasureFailure::NoBlob || m.status.cause == MeasureFailure::NoContrast;
  if (!m.status.ok() && !none) return StepResult::failed("blobs not searched: " + m.status.message);

  std::vector<Blob> kept;
  for (const Blob& blob : m.blobs)
    if (insideRect(rect, blob.centroid)) kept.push_back(blob);
  StepResult r;
  if (m.partial) r.note = "part of the blob rectangle lies outside the image: searched inside only";
  if (kept.empty()) {
    if (b.required)
      return StepResult::failed(
          "no blob found: " +
          (m.status.ok() ? std::string("none has its centre in the rectangle") : m.status.message));
    r.values["count"] = 0;
    r.values["presence"] = 0;
    r.point = cv::Point2d(rect.cx, rect.cy);
    return r;
  }
  const Blob& largest = kept.front();  // the tool sorts by area
  r.values["count"] = static_cast<double>(kept.size());
  r.values["presence"] = 1;
  if (plane) {
    const auto inPlane = blobInPlane(largest, *plane);
    if (!inPlane)
      return StepResult::failed("blob not measured: it does not map into the measuring plane");
    r.lengthsInMm = true;
    r.values["area"] = inPlane->areaMm2;
    r.point = plane->toImage(inPlane->centreMm);
  } else {
    r.values["area"] = largest.area;
    r.point = largest.centroid;
  }
  for (const Blob& blob : kept) {
    const cv::Rect& box = blob.bbox;
    part.overlay.polygon({{box.x - 0.5, box.y - 0.5},
                          {box.x + box.width - 0.5, box.y - 0.5},
                          {box.x + box.width - 0.5, box.y + box.height - 0.5},
                          {box.x - 0.5, box.y + box.height - 0.5}},
                         true);
    part.overlay.cross(blob.centroid, 3, true);
  }
  return r;
}

}  // namespace facet::service
