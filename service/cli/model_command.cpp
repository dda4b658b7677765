// facet model create: trains a shape model from a template image and writes it to a model file.
#include <cmath>
#include <iostream>
#include <optional>
#include <sstream>
#include <vector>

#include "algorithms/geometry/pose2d.hpp"
#include "algorithms/shape/shape_model.hpp"
#include "algorithms/shape/shape_model_file.hpp"
#include "service/cli/command_line.hpp"

namespace facet::cli {
namespace {

struct ModelOptions {
  std::string image;
  std::string roi;
  std::string angleRange;
  std::string scaleRange;
  int levels = 0;
  double minContrast = ShapeModelParams{}.minContrast;
  std::optional<int> minComponent;  // unset = automatic
  std::string edgeEstimator = "auto";
  std::string out;
  bool json = false;
};

// "a,b,c" -> numbers; exactly `count` of them or an InputError naming the option.
std::vector<double> parseList(const std::string& text, std::size_t count,
                              const std::string& option) {
  std::vector<double> values;
  std::istringstream in(text);
  std::string item;
  while (std::getline(in, item, ',')) {
    std::size_t used = 0;
    try {
      values.push_back(std::stod(item, &used));
    } catch (const std::exception&) {
      used = 0;
    }
    if (used == 0 || used != item.size())
      throw InputError(option + ": \"" + item + "\" is not a number (got \"" + text + "\")");
  }
  if (values.size() != count)
    throw InputError(option + " needs " + std::to_string(count) +
                     " comma-separated numbers (got \"" + text + "\")");
  return values;
}

void run(const ModelOptions& o) {
  const cv::Mat image = readGreyImage(o.image);
  ShapeModelParams p;
  if (!o.roi.empty()) {
    const auto r = parseList(o.roi, 4, "--roi");
    p.roi = cv::Rect(cvRound(r[0]), cvRound(r[1]), cvRound(r[2]), cvRound(r[3]));
  }
  if (!o.angleRange.empty()) {
    const auto a = parseList(o.angleRange, 2, "--angle-range");
    if (a[1] < a[0]) throw InputError("--angle-range: the end must not lie before the start");
    p.angleStart = radians(a[0]);
    p.angleExtent = radians(a[1] - a[0]);
  }
  if (!o.scaleRange.empty()) {
    const auto s = parseList(o.scaleRange, 2, "--scale-range");
    p.scaleMin = s[0];
    p.scaleMax = s[1];
  }
  p.numLevels = o.levels;
  p.minContrast = o.minContrast;
  p.minComponentSize = o.minComponent;
  if (o.edgeEstimator == "profile")
    p.edgeEstimator = EdgeEstimator::ProfileFit;
  else if (o.edgeEstimator == "zero-crossing")
    p.edgeEstimator = EdgeEstimator::FacetZeroCrossing;

  ShapeModel model;
  try {
    model = createShapeModel(image, p);
  } catch (const ShapeModelError& e) {
    throw InputError(o.image + ": " + e.what());
  }
  try {
    saveShapeModel(model, o.out);
  } catch (const ShapeModelFileError& e) {
    throw InputError(e.what());
  }
  if (o.json) {
    // What the automatic parameters chose, so that a user can see (and fix) them.
    nlohmann::json levels = nlohmann::json::array();
    for (const auto& l : model.levels)
      levels.push_back({{"points", l.points.size()}, {"angle_step", degrees(l.angleStep)}});
    nlohmann::json symmetries = nlohmann::json::array();
    for (const auto& s : model.symmetries)
      symmetries.push_back({{"angle", degrees(s.angle)}, {"score", s.score}});
    // Shifts (template pixels) whose neighbours the search tracks beside each top-level candidate.
    nlohmann::json periods = nlohmann::json::array();
    for (const auto& p : model.trackedPeriods)
      periods.push_back({{"shift", {p.shift.x, p.shift.y}}, {"score", p.score}});
    // The training test's pose errors (null for a copy not found: JSON has no infinity).
    nlohmann::json trials = nlohmann::json::object();
    for (const auto& t : model.edgeEstimatorTrials)
      trials[edgeEstimatorName(t.estimator)] =
          std::isfinite(t.poseError) ? nlohmann::json(t.poseError) : nlohmann::json();
    // The automatic pyramid's tests, deepest first: a depth refused for the period of the part's
    // pattern (its shift in template pixels; no copies searched), or the copies it lost.
    nlohmann::json pyramidTrials = nlohmann::json::array();
    for (const auto& t : model.pyramidTrials)
      pyramidTrials.push_back(
          t.period ? nlohmann::json{{"levels", t.levels},
                                    {"period", {t.period->shift.x, t.period->shift.y}},
                                    {"period_score", t.period->score}}
                   : nlohmann::json{{"levels", t.levels}, {"copies_lost", t.copiesLost}});
    printJson(
        {{"model", o.out},
         {"levels", model.numLevels()},
         {"levels_chosen", o.levels == 0 ? "automatic" : "--levels"},
         {"pyramid", levels},
         {"pyramid_trials", pyramidTrials},
         {"points", model.levels.front().points.size()},
         {"subpixel_points", model.finePoints.size()},
         {"reference", {model.referencePoint.x, model.referencePoint.y}},
         {"angle_step", degrees(model.levels.front().angleStep)},
         {"contrast_low", model.contrastLow},
         {"contrast_high", model.contrastHigh},
         {"min_contrast", model.minContrast},
         {"min_component", model.minComponentSize},
         {"min_component_chosen", o.minComponent ? "--min-component" : "automatic"},
         {"near_symmetries", symmetries},
         {"tracked_periods", periods},
         {"edge_estimator", edgeEstimatorName(model.edgeEstimator)},
         {"edge_estimator_chosen", o.edgeEstimator == "auto" ? "automatic" : "--edge-estimator"},
         {"edge_estimator_trials", trials}});
  } else {
    std::cout << "wrote " << o.out << ": " << model.numLevels() << " levels, "
              << model.levels.front().points.size() << " points on level 0, "
              << model.finePoints.size() << " subpixel points, angle step "
              << degrees(model.levels.front().angleStep) << " deg, edges by "
              << edgeEstimatorName(model.edgeEstimator) << "\n";
  }
}

}  // namespace

void addModelCommand(CLI::App& app) {
  auto* model = app.add_subcommand("model", "Shape models");
  model->require_subcommand(1);
  auto* create = model->add_subcommand("create", "Train a shape model from a template image");
  auto o = std::make_shared<ModelOptions>();
  create->add_option("--image", o->image, "Template image (8/16-bit grey)")->required();
  create->add_option("--roi", o->roi,
                     "Region of the part: x,y,w,h in pixels (default: whole image)");
  create->add_option("--angle-range", o->angleRange,
                     "Angles to search: a0,a1 in degrees (default: all)");
  create->add_option("--scale-range", o->scaleRange, "Scales to search: s0,s1 (default: 1,1)");
  create->add_option("--levels", o->levels, "Pyramid levels (default 0 = automatic)");
  create->add_option("--min-contrast", o->minContrast,
                     "Weakest gradient used, grey levels per pixel (default 5)");
  create
      ->add_option("--min-component", o->minComponent,
                   "Shortest edge contour kept, pixels; shorter ones (specks, dust, one sample's "
                   "texture) are left out (default: automatic, 10 unless the short contours are "
                   "most of the template's edges; 0 = keep all)")
      ->check(CLI::Range(0, 1000000));
  create
      ->add_option("--edge-estimator", o->edgeEstimator,
                   "Subpixel edges of the refinement: profile (blurred-step fit), zero-crossing "
                   "(facet model alone) or auto (default: the one that finds the template's own "
                   "pose again on turned copies of it)")
      ->check(CLI::IsMember({"auto", "profile", "zero-crossing"}));
  create->add_option("--out", o->out, "Model file to write")->required();
  create->add_flag("--json", o->json, "Print JSON");
  create->callback([o] { run(*o); });
}

}  // namespace facet::cli
