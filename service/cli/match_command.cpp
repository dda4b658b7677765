// facet match: finds a shape model in an image and prints the matches' poses.
#include <chrono>
#include <iostream>
#include <numbers>
#include <sstream>

#include "algorithms/shape/find_shape_model.hpp"
#include "algorithms/shape/shape_model_file.hpp"
#include "service/cli/command_line.hpp"

namespace facet::cli {
namespace {

struct MatchOptions {
  std::string model;
  std::string image;
  FindParams find;
  std::string angleRange;
  std::string scaleRange;
  std::string polarity = "use";
  std::string subpixel = "least_squares";
  bool json = false;
};

std::pair<double, double> parsePair(const std::string& text, const std::string& option) {
  std::istringstream in(text);
  double a = 0, b = 0;
  char comma = 0;
  if (!(in >> a >> comma >> b) || comma != ',' || !(in >> std::ws).eof())
    throw InputError(option + " must be two numbers a,b (got \"" + text + "\")");
  return {a, b};
}

std::string number(double value) {
  std::ostringstream out;
  out << value;
  return out.str();
}

// The search options, judged under the names the user typed (the search itself would name its
// own parameters and blame the image).
void checkSearchOptions(const FindParams& find) {
  if (!(find.minScore > 0.0 && find.minScore <= 1.0))
    throw InputError("--min-score must lie in (0, 1] (got " + number(find.minScore) + ")");
  if (find.numMatches < 0)
    throw InputError("--num-matches must be 0 (all) or more (got " +
                     std::to_string(find.numMatches) + ")");
  if (!(find.maxOverlap >= 0.0 && find.maxOverlap <= 1.0))
    throw InputError("--max-overlap must lie in [0, 1] (got " + number(find.maxOverlap) + ")");
  if (!(find.greediness >= 0.0 && find.greediness <= 1.0))
    throw InputError("--greediness must lie in [0, 1] (got " + number(find.greediness) + ")");
  if (!(find.refineScaleTolerance >= 0.0 && find.refineScaleTolerance <= kMaxScaleTolerance))
    throw InputError("--scale-tolerance must lie in [0, " + number(kMaxScaleTolerance) + "] (got " +
                     number(find.refineScaleTolerance) + ")");
  if (find.maxDeformation < 0 || find.maxDeformation > kMaxDeformation)
    throw InputError("--max-deformation must lie in [0, " + std::to_string(kMaxDeformation) +
                     "] pixels (got " + std::to_string(find.maxDeformation) + ")");
}

constexpr double kTurn = 2.0 * std::numbers::pi;

// The search never leaves the range the model was trained for: a requested range reaching
// beyond it is cut, silently on the search's side. Says so, in the user's units.
std::vector<std::string> rangeWarnings(const ShapeModel& model, const MatchOptions& o) {
  std::vector<std::string> warnings;
  const double tolerance = 1e-9;
  if (!o.angleRange.empty() && model.angleExtent < kTurn - tolerance) {
    const double a0 = o.find.angleStart, a1 = o.find.angleStart + o.find.angleExtent;
    const double m0 = model.angleStart, m1 = model.angleStart + model.angleExtent;
    bool inside = false, meets = false;
    for (int k = -2; k <= 2; ++k) {
      inside = inside || (a0 + k * kTurn >= m0 - tolerance && a1 + k * kTurn <= m1 + tolerance);
      meets = meets || (a0 + k * kTurn <= m1 && a1 + k * kTurn >= m0);
    }
    const std::string trained = number(degrees(m0)) + "," + number(degrees(m1)) + " deg";
    if (!inside)
      warnings.push_back("--angle-range " + o.angleRange +
                         (meets ? " is cut to the model's trained range " + trained
                                : " lies outside the model's trained range " + trained +
                                      ": no angle is searched") +
                         " (train the model with a wider --angle-range to search more)");
  }
  if (!o.scaleRange.empty() && (o.find.scaleMin < model.scaleMin - tolerance ||
                                o.find.scaleMax > model.scaleMax + tolerance)) {
    const bool meets = o.find.scaleMin <= model.scaleMax && o.find.scaleMax >= model.scaleMin;
    const std::string trained = number(model.scaleMin) + "," + number(model.scaleMax);
    warnings.push_back(
        "--scale-range " + o.scaleRange +
        (meets ? " is cut to the model's trained range " + trained
               : " lies outside the model's trained range " + trained + ": no scale is searched") +
        " (train the model with a wider --scale-range to search more)");
  }
  return warnings;
}

void run(MatchOptions o) {
  checkSearchOptions(o.find);
  ShapeModel model;
  try {
    model = loadShapeModel(o.model);
  } catch (const ShapeModelFileError& e) {
    throw InputError(e.what());
  }
  const cv::Mat image = readGreyImage(o.image);

  if (o.polarity == "use")
    o.find.polarity = Polarity::Use;
  else if (o.polarity == "ignore_global")
    o.find.polarity = Polarity::IgnoreGlobal;
  else if (o.polarity == "ignore_local")
    o.find.polarity = Polarity::IgnoreLocal;
  else
    throw InputError("--polarity must be use, ignore_global or ignore_local (got \"" + o.polarity +
                     "\")");
  if (o.find.maxDeformation > 0 && o.find.polarity == Polarity::IgnoreGlobal)
    throw InputError(
        "--max-deformation cannot be combined with --polarity ignore_global (use "
        "ignore_local)");
  if (o.subpixel == "none")
    o.find.subpixel = SubpixelMode::None;
  else if (o.subpixel == "interpolation")
    o.find.subpixel = SubpixelMode::Interpolation;
  else if (o.subpixel == "least_squares")
    o.find.subpixel = SubpixelMode::LeastSquares;
  else
    throw InputError("--subpixel must be none, interpolation or least_squares (got \"" +
                     o.subpixel + "\")");
  if (!o.angleRange.empty()) {
    const auto [a0, a1] = parsePair(o.angleRange, "--angle-range");
    if (a1 < a0) throw InputError("--angle-range: the end must not lie before the start");
    o.find.angleStart = radians(a0);
    o.find.angleExtent = radians(a1 - a0);
  }
  if (!o.scaleRange.empty()) {
    const auto [s0, s1] = parsePair(o.scaleRange, "--scale-range");
    if (!(s0 > 0 && s1 >= s0)) throw InputError("--scale-range must satisfy 0 < s0 <= s1");
    o.find.scaleMin = s0;
    o.find.scaleMax = s1;
  }

  const std::vector<std::string> warnings = rangeWarnings(model, o);

  const auto t0 = std::chrono::steady_clock::now();
  std::vector<ShapeMatch> matches;
  try {
    matches = findShapeModel(image, model, o.find);
  } catch (const std::invalid_argument& e) {
    throw InputError(o.image + ": " + e.what());
  }
  const double ms =
      std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();

  if (o.json) {
    nlohmann::json list = nlohmann::json::array();
    for (const auto& m : matches)
      list.push_back({{"x", m.x},
                      {"y", m.y},
                      {"angle", degrees(m.angle)},
                      {"scale", m.scale},
                      {"score", m.score}});
    printJson({{"matches", list}, {"warnings", warnings}, {"time_ms", ms}});
  } else {
    for (const auto& w : warnings) std::cerr << "facet: warning: " << w << "\n";
    std::cout << matches.size() << " match(es) in " << ms << " ms\n";
    for (const auto& m : matches)
      std::cout << "  x " << m.x << "  y " << m.y << "  angle " << degrees(m.angle)
                << " deg  scale " << m.scale << "  score " << m.score << "\n";
  }
}

}  // namespace

void addMatchCommand(CLI::App& app) {
  auto* cmd = app.add_subcommand("match", "Find a shape model in an image");
  auto o = std::make_shared<MatchOptions>();
  cmd->add_option("--model", o->model, "Model file from `facet model create`")->required();
  cmd->add_option("--image", o->image, "Image to search (8/16-bit grey)")->required();
  cmd->add_option("--min-score", o->find.minScore, "Lowest score, 0..1 (default 0.7)");
  cmd->add_option("--num-matches", o->find.numMatches, "Matches to return, 0 = all (default 1)");
  cmd->add_option("--max-overlap", o->find.maxOverlap,
                  "Largest overlap of two matches, 0..1 (default 0.5)");
  cmd->add_option("--greediness", o->find.greediness, "0 = safe .. 1 = fast (default 0: safe)");
  cmd->add_option("--angle-range", o->angleRange,
                  "Angles to search: a0,a1 in degrees (default: the model's)");
  cmd->add_option("--scale-range", o->scaleRange, "Scales to search: s0,s1 (default: the model's)");
  cmd->add_option("--scale-tolerance", o->find.refineScaleTolerance,
                  "Scale change the subpixel fit may find on a part whose model has one scale, "
                  "relative, 0..0.1 (default 0.02; 0 = the model's scale)");
  cmd->add_option("--max-deformation", o->find.maxDeformation,
                  "Pixels by which the part's contour may differ from the model's, 0.." +
                      std::to_string(kMaxDeformation) +
                      " (default 0: rigid; not with --polarity ignore_global)");
  cmd->add_option("--polarity", o->polarity, "use | ignore_global | ignore_local (default use)");
  cmd->add_option("--subpixel", o->subpixel,
                  "none | interpolation | least_squares (default least_squares)");
  cmd->add_flag("--json", o->json, "Print JSON");
  cmd->callback([o] { run(*o); });
}

}  // namespace facet::cli
