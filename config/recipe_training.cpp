#include "config/recipe_training.hpp"

#include <opencv2/imgcodecs.hpp>

#include "algorithms/geometry/pose2d.hpp"
#include "algorithms/image/grey_image.hpp"
#include "algorithms/shape/shape_model.hpp"
#include "algorithms/shape/shape_model_file.hpp"
#include "config/training_record.hpp"

namespace facet::config {
namespace {

TrainedModel train(const Step& step, const std::filesystem::path& templateFile,
                   const std::optional<cv::Rect2d>& region, const AngleRange& angles,
                   const std::filesystem::path& modelFile) {
  const std::string what = "step '" + step.id + "': ";
  cv::Mat image = cv::imread(templateFile.string(), cv::IMREAD_UNCHANGED);
  if (image.empty()) throw TrainingError(what + templateFile.string() + ": cannot read the image");
  image = toGrey(image);

  ShapeModelParams params;
  if (region)
    params.roi = cv::Rect(cvRound(region->x), cvRound(region->y), cvRound(region->width),
                          cvRound(region->height));
  params.angleStart = radians(angles.low);
  params.angleExtent = radians(angles.high - angles.low);
  ShapeModel model;
  try {
    model = createShapeModel(image, params);
  } catch (const std::exception& e) {
    throw TrainingError(what + templateFile.string() + ": " + e.what());
  }
  try {
    std::filesystem::create_directories(modelFile.parent_path());
    saveShapeModel(model, modelFile);
    writeTrainingRecord(modelFile, templateFile, trainingParameters(step));
  } catch (const std::exception& e) {
    throw TrainingError(what + e.what());
  }
  return {step.id, modelFile, model.numLevels(),
          model.levels.empty() ? 0 : model.levels.front().points.size()};
}

}  // namespace

std::vector<TrainedModel> trainRecipe(const Recipe& recipe) {
  std::vector<TrainedModel> trained;
  for (const auto& step : recipe.steps) {
    if (const auto* a = std::get_if<AlignStep>(&step.params)) {
      if (a->method == AlignStep::Method::Shape && a->model)
        trained.push_back(train(step, a->reference, a->region, a->angleRange, *a->model));
    } else if (const auto* s = std::get_if<ShapeStep>(&step.params)) {
      trained.push_back(train(step, s->templateImage, s->region, s->angleRange, s->model));
    }
  }
  return trained;
}

}  // namespace facet::config
