#include "service/engine/steps/shape_step.hpp"

#include <opencv2/imgproc.hpp>

#include "algorithms/registration/register_images.hpp"
#include "algorithms/shape/find_shape_model.hpp"
#include "config/recipe_format.hpp"
#include "service/engine/frame_maps.hpp"
#include "service/engine/steps/pose_fields.hpp"
#include "service/engine/steps/pose_offset.hpp"
#include "service/engine/steps/shape_model_resource.hpp"

namespace facet::service {
namespace {

using config::Quantity;

ShapeTraining trainingOf(const ShapeParams& s) {
  return {s.templateImage, s.region, s.angleRange, s.model};
}

}  // namespace

ShapeStep::ShapeStep() : TableStep({.point = true, .pose = true, .line = true}) {
  addRelativeTo(fields_);
  fields_.path("template", &ShapeParams::templateImage,
               "Image the model is trained from, relative to the recipe.", true);
  fields_.rect("region", &ShapeParams::region,
               "[x, y, width, height] of the template that holds the part, pixels.");
  fields_.path("model", &ShapeParams::model, "Trained model file, written by `facet recipe train`.",
               true, true);
  addSearch(fields_);
  fields_.integer("num_matches", &ShapeParams::numMatches, "Most matches searched.",
                  {.minimum = 1.0, .maximum = 100.0});
  fields_.number("max_overlap", &ShapeParams::maxOverlap, "Largest overlap of two matches, 0..1.",
                 {.minimum = 0.0, .maximum = 1.0});
  fields_.number("scale_tolerance", &ShapeParams::scaleTolerance,
                 "Scale change the subpixel fit may find on a part that differs a little from its "
                 "template (lens, working distance), relative; 0 = the template's scale.",
                 {.minimum = 0.0, .maximum = kMaxScaleTolerance});
  fields_.integer("max_deformation", &ShapeParams::maxDeformation,
                  "Pixels by which a part's contours may differ from the template's (a moulded "
                  "part, a lens set off-centre in its housing); scores then count a model point "
                  "met that far off. 0 = rigid. Costs search time: try 1 first.",
                  {.minimum = 0.0, .maximum = double(kMaxDeformation)});
  checks_ = {"shape checks",
             "",
             {config::checkField("count", Quantity::Count, "Number of matches found.", 0.0),
              config::checkField("x", Quantity::Length, kOffsetXDoc),
              config::checkField("y", Quantity::Length, kOffsetYDoc),
              config::checkField("angle", Quantity::Angle,
                                 "Rotation of the best match, degrees (in the measuring plane "
                                 "when the station has one)."),
              config::checkField("score", Quantity::Score, "Score of the best match, 0..1.", 0.0)}};
  describe("shape", "Finds a trained shape model and checks count and pose.");
}

std::shared_ptr<const config::StepResources> ShapeStep::prepare(const config::Step& step,
                                                                config::StepReading& in) const {
  return prepareShapeModel(trainingOf(step.as<ShapeParams>()), in, "template");
}

std::vector<config::TrainedModel> ShapeStep::train(const config::Step& step) const {
  return {trainShapeModel(step, trainingOf(step.as<ShapeParams>()))};
}

// A match placed relative to an earlier pose has no picture of the whole part.
cv::Mat ShapeStep::pictureOfPart(const config::Step& step) const {
  if (!step.resources || step.as<ShapeParams>().relativeTo) return {};
  return step.resourcesAs<ShapeModelResource>().templateGrey;
}

StepResult ShapeStep::run(const config::Step& step, StepContext& part) const {
  const auto& s = step.as<ShapeParams>();
  cv::Rect search = clampRect(s.searchRegion, part.grey.size());
  config::AngleRange angles = s.angleRange;
  if (s.relativeTo) {
    // Relative to an earlier pose: search only where that step's reference view lies in the
    // live image, with the angle range turned by that step's rotation.
    const StepResult& base = part.done.at(*s.relativeTo);
    if (base.referenceView) {
      std::vector<cv::Point2f> mapped;
      for (const auto& c : outerCorners(cv::Rect(*base.referenceView)))
        mapped.emplace_back(mapPoint(*base.refToImage, c));
      const int margin = 8;
      search &=
          cv::boundingRect(mapped) + cv::Size(2 * margin, 2 * margin) - cv::Point(margin, margin);
    }
    if (base.angleDeg) angles = {angles.low + *base.angleDeg, angles.high + *base.angleDeg};
  }
  if (search.empty()) return StepResult::failed("search region outside the image");
  part.overlay.polygon(outerCorners(search), true, true);
  const auto& shape = step.resourcesAs<ShapeModelResource>();
  const auto matches = findShapeModel(part.grey(search), shape.model,
                                      findParamsFor(s.minScore, s.numMatches, s.maxOverlap, angles,
                                                    s.scaleTolerance, s.maxDeformation));
  StepResult r;
  r.values["count"] = static_cast<double>(matches.size());
  for (const auto& m : matches) drawContour(part.overlay, m.contour, search.tl(), true);
  if (matches.empty()) {
    // Nothing found: the count is still a valid measurement (it may be checked against 0).
    if (step.check("count") != nullptr && step.checks.size() == 1) return r;
    return StepResult::failed("no match above min score " + std::to_string(s.minScore));
  }
  // Relative to an earlier pose, the nominal position moves with the part.
  const cv::Point2d nominal = mapPoint(part.frameOf(s.relativeTo), shape.home);
  const ShapeMatch& best = matches[0];
  const cv::Point2d at(best.x + search.x, best.y + search.y);
  r.angleDeg = degrees(best.angle);
  if (!setPoseOffset(r, part.calibration.worldMapping(), nominal, at, *r.angleDeg))
    return StepResult::failed("the match does not map into the measuring plane");
  r.values["score"] = best.score;
  r.refToImage = translation(cv::Point2d(search.tl())) * poseMap(best.pose(), shape.home);
  r.referenceView =
      cv::Rect2d(shape.home - shape.model.referencePoint, cv::Size2d(shape.model.templateSize));
  r.point = at;
  part.overlay.cross(at, 8, true);
  return r;
}

}  // namespace facet::service
