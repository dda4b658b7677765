#include "service/engine/steps/shape_model_resource.hpp"

#include "algorithms/geometry/pose2d.hpp"
#include "algorithms/image/grey_image.hpp"
#include "algorithms/shape/shape_model_file.hpp"
#include "camera/image_codecs.hpp"
#include "config/recipe_loader.hpp"
#include "config/recipe_training.hpp"
#include "config/training_record.hpp"
#include "config/yaml_validation.hpp"

namespace facet::service {
namespace {

std::string rectText(const std::optional<cv::Rect2d>& r) {
  using config::formatNumber;
  if (!r) return "all";
  return formatNumber(r->x) + "," + formatNumber(r->y) + "," + formatNumber(r->width) + "," +
         formatNumber(r->height);
}

// The training parameters as canonical text: a change to them makes the model stale.
std::string parametersText(const ShapeTraining& t) {
  return "shape;region=" + rectText(t.region) + ";angle=" + config::formatNumber(t.angles.low) +
         "," + config::formatNumber(t.angles.high);
}

}  // namespace

std::shared_ptr<const ShapeModelResource> prepareShapeModel(const ShapeTraining& training,
                                                            config::StepReading& in,
                                                            const std::string& templateKey) {
  // A missing or empty key, or a file that is not there, was reported by the validator or the
  // reading (the path is then empty): nothing to load, and no second error for it.
  if (!in[templateKey] || !in["model"] || training.templateImage.empty()) return nullptr;
  const cv::Mat image = readImage(training.templateImage, cv::IMREAD_UNCHANGED);
  if (image.empty()) {
    in.error(in[templateKey], "'" + templateKey + "' file '" + in[templateKey].Scalar() +
                                  "' cannot be read as an image");
    return nullptr;
  }
  if (const auto& r = training.region; r && (r->x < 0 || r->y < 0 || r->x + r->width > image.cols ||
                                             r->y + r->height > image.rows)) {
    in.error(in["region"], "'region' reaches outside the " + templateKey + " image (" +
                               std::to_string(image.cols) + "x" + std::to_string(image.rows) +
                               " pixels)");
    return nullptr;
  }
  if (training.model.empty()) return nullptr;  // reported, as above
  in.addDependency(config::trainingRecordPath(training.model));
  if (!in.options().requireTrainedModels) return nullptr;

  const YAML::Node key = in["model"];
  const std::string what = "model '" + key.Scalar() + "' ";
  const std::string advice = "; run `facet recipe train " + in.recipeFile().string() + "`";
  const config::ModelStatus status =
      config::modelStatus(training.model, training.templateImage, parametersText(training));
  auto resource = std::make_shared<ShapeModelResource>();
  if (status.state != config::ModelState::Missing) {
    // A file that is no model at all (or one of another facet version) is that, not "stale".
    try {
      resource->model = loadShapeModel(training.model);
    } catch (const std::exception& e) {
      in.error(key, what + "cannot be loaded: " + e.what() + advice);
      return nullptr;
    }
  }
  switch (status.state) {
    case config::ModelState::Missing:
      in.error(key, what + status.detail + advice);
      return nullptr;
    case config::ModelState::Stale:
      in.error(key, what + "is stale: " + status.detail + advice);
      return nullptr;
    case config::ModelState::Untracked:
      in.warning(key, what + status.detail + ", so staleness is unknown" + advice);
      break;
    case config::ModelState::Fresh:
      break;
  }

  const cv::Point2d offset =
      training.region ? cv::Point2d(cvRound(training.region->x), cvRound(training.region->y))
                      : cv::Point2d();
  resource->home = resource->model.referencePoint + offset;
  resource->templateGrey = toGrey(image);
  return resource;
}

FindParams findParamsFor(double minScore, int numMatches, double maxOverlap,
                         const config::AngleRange& range, double scaleTolerance,
                         int maxDeformation) {
  FindParams p;
  p.refineScaleTolerance = scaleTolerance;
  p.maxDeformation = maxDeformation;
  p.minScore = minScore;
  p.numMatches = numMatches;
  p.maxOverlap = maxOverlap;
  p.angleStart = radians(range.low);
  p.angleExtent = radians(range.high - range.low);
  p.subpixel = SubpixelMode::LeastSquares;
  return p;
}

void drawContour(Overlay& overlay, const std::vector<cv::Point2d>& contour, cv::Point offset,
                 bool pass) {
  for (const auto& p : contour) overlay.polyline({{p.x + offset.x, p.y + offset.y}}, pass);
}

config::TrainedModel trainShapeModel(const config::Step& step, const ShapeTraining& training) {
  const std::string what = "step '" + step.id + "': ";
  const std::string file = training.templateImage.string();
  const cv::Mat image = readImage(file, cv::IMREAD_UNCHANGED);
  if (image.empty()) throw config::TrainingError(what + file + ": cannot read the image");
  ShapeModelParams params;
  if (const auto& r = training.region)
    params.roi = cv::Rect(cvRound(r->x), cvRound(r->y), cvRound(r->width), cvRound(r->height));
  params.angleStart = radians(training.angles.low);
  params.angleExtent = radians(training.angles.high - training.angles.low);
  ShapeModel model;
  try {
    model = createShapeModel(toGrey(image), params);
  } catch (const std::exception& e) {
    throw config::TrainingError(what + file + ": " + e.what());
  }
  try {
    std::filesystem::create_directories(training.model.parent_path());
    saveShapeModel(model, training.model);
    config::writeTrainingRecord(training.model, training.templateImage, parametersText(training));
  } catch (const std::exception& e) {
    throw config::TrainingError(what + e.what());
  }
  return {step.id, training.model, model.numLevels(),
          model.levels.empty() ? 0 : model.levels.front().points.size()};
}

}  // namespace facet::service
