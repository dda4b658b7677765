#include "service/engine/steps/align_step.hpp"

#include "algorithms/image/grey_image.hpp"
#include "algorithms/registration/register_images.hpp"
#include "algorithms/shape/find_shape_model.hpp"
#include "camera/image_codecs.hpp"
#include "config/recipe_format.hpp"
#include "service/engine/frame_maps.hpp"
#include "service/engine/steps/pose_fields.hpp"
#include "service/engine/steps/pose_offset.hpp"
#include "service/engine/steps/shape_model_resource.hpp"

namespace facet::service {
namespace {

using config::Quantity;

struct ReferenceImage : config::StepResources {
  cv::Mat grey;
};

ShapeTraining trainingOf(const AlignParams& a) {
  return {a.reference, a.region, a.angleRange, a.model};
}

// x, y: offset of the reference point `home` from its nominal place; angle: rotation (in the
// measuring plane when the station has one, pose_offset.hpp).
StepResult withPoseValues(StepResult r, cv::Point2d home, const StepContext& part) {
  const cv::Point2d found = mapPoint(*r.refToImage, home);
  r.angleDeg = rotationDeg(*r.refToImage, home);
  r.point = found;
  if (!setPoseOffset(r, part.calibration.worldMapping(), home, found, *r.angleDeg))
    return StepResult::failed("the part's place does not map into the measuring plane");
  return r;
}

}  // namespace

AlignStep::AlignStep() : TableStep({.point = true, .pose = true, .line = true}) {
  using M = AlignParams::Method;
  fields_.choice(
      "method", &AlignParams::method, {{"registration", M::Registration}, {"shape", M::Shape}},
      "registration (features of a reference image) or shape (a trained shape model).", true);
  fields_.path("reference", &AlignParams::reference,
               "Reference image (registration) or template image the model is trained from "
               "(shape), relative to the recipe.",
               true);
  fields_.rect("region", &AlignParams::region,
               "[x, y, width, height] of the reference used, pixels; default: all of it.");
  fields_.path("model", &AlignParams::model,
               "Trained shape model (method shape), written by `facet recipe train`.", false, true);
  addSearch(fields_);
  checks_ = {"align checks",
             "",
             {config::checkField("x", Quantity::Length, kOffsetXDoc),
              config::checkField("y", Quantity::Length, kOffsetYDoc),
              config::checkField("angle", Quantity::Angle,
                                 "Rotation of the part, degrees (in the measuring plane when "
                                 "the station has one)."),
              config::checkField("score", Quantity::Score, "Match score, 0..1.", 0.0)}};
  describe("align",
           "Finds the part and gives the pose later steps follow: log-polar "
           "registration to a reference image, or a shape match.");
}

void AlignStep::crossCheck(const AlignParams& a, config::StepReading& in) const {
  if (in["model"] && a.method != AlignParams::Method::Shape)
    in.warning(in["model"], "'model' is only used with method shape");
  if (!in["model"] && a.method == AlignParams::Method::Shape && in["method"])
    in.error(in["method"], "method shape needs a 'model' file (written by `facet recipe train`)");
}

std::shared_ptr<const config::StepResources> AlignStep::prepare(const config::Step& step,
                                                                config::StepReading& in) const {
  const auto& a = step.as<AlignParams>();
  // Reported by the validator, or by the reading (an empty path: a file that is not there).
  if (!in["reference"] || a.reference.empty()) return nullptr;
  if (a.method == AlignParams::Method::Shape)
    return prepareShapeModel(trainingOf(a), in, "reference");
  auto reference = std::make_shared<ReferenceImage>();
  const cv::Mat image = readImage(a.reference, cv::IMREAD_UNCHANGED);
  if (image.empty()) {
    in.error(in["reference"],
             "'reference' file '" + in["reference"].Scalar() + "' cannot be read as an image");
    return nullptr;
  }
  if (const auto& r = a.region; r && (r->x < 0 || r->y < 0 || r->x + r->width > image.cols ||
                                      r->y + r->height > image.rows)) {
    in.error(in["region"], "'region' reaches outside the reference image (" +
                               std::to_string(image.cols) + "x" + std::to_string(image.rows) +
                               " pixels)");
    return nullptr;
  }
  reference->grey = toGrey(image);
  return reference;
}

std::vector<config::TrainedModel> AlignStep::train(const config::Step& step) const {
  const auto& a = step.as<AlignParams>();
  if (a.method != AlignParams::Method::Shape || a.model.empty()) return {};
  return {trainShapeModel(step, trainingOf(a))};
}

cv::Mat AlignStep::pictureOfPart(const config::Step& step) const {
  if (!step.resources) return {};
  if (step.as<AlignParams>().method == AlignParams::Method::Shape)
    return step.resourcesAs<ShapeModelResource>().templateGrey;
  return step.resourcesAs<ReferenceImage>().grey;
}

StepResult AlignStep::run(const config::Step& step, StepContext& part) const {
  const auto& a = step.as<AlignParams>();
  const cv::Rect search = clampRect(a.searchRegion, part.grey.size());
  if (search.empty()) return StepResult::failed("search region outside the image");
  const cv::Mat live = part.grey(search);
  part.overlay.polygon(outerCorners(search), true, true);
  StepResult r;
  if (a.method == AlignParams::Method::Shape) {
    const auto& shape = step.resourcesAs<ShapeModelResource>();
    const auto matches =
        findShapeModel(live, shape.model, findParamsFor(a.minScore, 1, 0.5, a.angleRange));
    if (matches.empty())
      return StepResult::failed("part not found (no match above min score " +
                                std::to_string(a.minScore) + ")");
    r.refToImage = translation(cv::Point2d(search.tl())) * poseMap(matches[0].pose(), shape.home);
    r.values["score"] = matches[0].score;
    r.referenceView =
        cv::Rect2d(shape.home - shape.model.referencePoint, cv::Size2d(shape.model.templateSize));
    drawContour(part.overlay, matches[0].contour, search.tl(), true);
    return withPoseValues(std::move(r), shape.home, part);
  }
  const cv::Mat& ref = step.resourcesAs<ReferenceImage>().grey;
  const cv::Rect region = clampRect(a.region, ref.size());
  // The whole reference view is registered: log-polar windows need room around each corner,
  // which a tight part region does not give. The region sets the nominal point and outline.
  RegistrationParams params;
  params.model = TransformModel::Similarity;
  const RegistrationResult reg = registerImages(ref, live, params);
  if (!reg.status.ok())
    return StepResult::failed("alignment failed: " + std::string(toString(reg.status.cause)));
  r.refToImage = translation(cv::Point2d(search.tl())) * reg.H;
  r.referenceView = cv::Rect2d(region);
  const double score =
      reg.matches.empty() ? 0.0 : static_cast<double>(reg.inliers.size()) / reg.matches.size();
  r.values["score"] = score;
  std::vector<cv::Point2d> outline;
  for (const auto& c : outerCorners(region)) outline.push_back(mapPoint(*r.refToImage, c));
  part.overlay.polygon(outline, score >= a.minScore);
  if (score < a.minScore)
    return StepResult::failed("alignment score " + std::to_string(score) + " below " +
                              std::to_string(a.minScore));
  const cv::Point2d home(region.x + (region.width - 1) / 2.0, region.y + (region.height - 1) / 2.0);
  return withPoseValues(std::move(r), home, part);
}

}  // namespace facet::service
