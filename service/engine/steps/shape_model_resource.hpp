#pragma once
// The trained shape model of a step that finds its part by shape (`align` with method shape,
// `shape`): checked against its training record and loaded once when the recipe is loaded,
// trained by `facet recipe train`.

#include <filesystem>
#include <memory>
#include <optional>
#include <string>

#include <opencv2/core.hpp>

#include "algorithms/shape/find_shape_model.hpp"
#include "algorithms/shape/shape_model.hpp"
#include "config/recipe.hpp"
#include "config/step_fields.hpp"
#include "config/step_reading.hpp"
#include "service/engine/overlay.hpp"

namespace facet::service {

struct ShapeModelResource : config::StepResources {
  ShapeModel model;
  cv::Point2d home;      // the model's reference point in its template image: the nominal position
  cv::Mat templateGrey;  // the template image, grey: a picture of the part (warmUp)
};

// What a shape model is trained from: the template image, the part of it, the angles searched.
struct ShapeTraining {
  std::filesystem::path templateImage;
  std::optional<cv::Rect2d> region;
  config::AngleRange angles;
  std::filesystem::path model;
};

// Checks the template image (readable, region inside it) and loads the model. A missing, stale
// or unreadable model is reported at the step's `model` key, unless the recipe is read for
// training (RecipeLoadOptions::requireTrainedModels off): then only the template is checked and
// the result is null. Null too after any error.
std::shared_ptr<const ShapeModelResource> prepareShapeModel(const ShapeTraining& training,
                                                            config::StepReading& in,
                                                            const std::string& templateKey);

// The search parameters of a step's shape model (least-squares subpixel poses).
FindParams findParamsFor(double minScore, int numMatches, double maxOverlap,
                         const config::AngleRange& range,
                         double scaleTolerance = FindParams{}.refineScaleTolerance,
                         int maxDeformation = FindParams{}.maxDeformation);

// A found contour (a point set, not an ordered polyline) drawn as dots, offset into the image.
void drawContour(Overlay& overlay, const std::vector<cv::Point2d>& contour, cv::Point offset,
                 bool pass);

// Trains the model, writes it and its training record. Throws config::TrainingError.
config::TrainedModel trainShapeModel(const config::Step& step, const ShapeTraining& training);

}  // namespace facet::service
