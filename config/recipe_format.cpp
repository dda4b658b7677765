#include "config/recipe_format.hpp"

namespace facet::config {
namespace {

using F = FieldType;

FieldSpec checkField(std::string name, Quantity quantity, std::string description,
                     std::optional<double> minimum = std::nullopt) {
  return {.name = std::move(name),
          .type = F::Object,
          .description = std::move(description),
          .minimum = minimum,
          .quantity = quantity};
}

FieldSpec relativeTo() {
  return {.name = "relative_to",
          .type = F::StepRef,
          .description =
              "Id of an earlier align, fiducials or shape step whose pose this step's "
              "positions follow; without it positions are pixels of the live image."};
}

FieldSpec minScore() {
  return {.name = "min_score",
          .type = F::Number,
          .description = "Lowest match score accepted, 0..1.",
          .minimum = 0.0,
          .maximum = 1.0,
          .exclusiveMinimum = true,
          .defaultValue = 0.7};
}

FieldSpec angleRange() {
  return {.name = "angle_range",
          .type = F::Range,
          .description =
              "[low, high] rotation searched, degrees, within [-180, 180]; relative to "
              "the relative_to step's angle when the step has one.",
          .minimum = -180.0,
          .maximum = 180.0,
          .defaultValue = {-180.0, 180.0}};
}

FieldSpec region(std::string description) {
  return {.name = "region", .type = F::Rect, .description = std::move(description), .minimum = 0.0};
}

FieldSpec searchRegion() {
  return {.name = "search_region",
          .type = F::Rect,
          .description =
              "[x, y, width, height] of the live image searched, pixels; default: "
              "all of it.",
          .minimum = 0.0};
}

// Keys every step has, followed by the kind's own keys and its checks.
ObjectSpec stepObject(std::string kind, std::string description, std::vector<FieldSpec> own,
                      const ObjectSpec* checks) {
  ObjectSpec spec{kind + " step", std::move(description), {}};
  spec.fields.push_back({.name = "id",
                         .type = F::Identifier,
                         .description = "Unique name of the step in the recipe "
                                        "([a-z][a-z0-9_]*); later steps refer to it.",
                         .required = true});
  spec.fields.push_back({.name = "kind",
                         .type = F::Enum,
                         .description = "Step kind.",
                         .required = true,
                         .choices = {kind}});
  spec.fields.push_back(
      {.name = "name", .type = F::String, .description = "Display name; default: the id."});
  for (auto& f : own) spec.fields.push_back(std::move(f));
  spec.fields.push_back({.name = "checks",
                         .type = F::Object,
                         .description = "Checked values of this step; the part fails when one "
                                        "is out of tolerance.",
                         .object = checks});
  return spec;
}

}  // namespace

RecipeFormat::RecipeFormat() {
  plcOutput = {"plc output",
               "Holding register the measured value is written to (see the station's "
               "register_map for the address base).",
               {{.name = "register",
                 .type = F::Integer,
                 .description = "First holding register.",
                 .required = true,
                 .minimum = 0.0,
                 .maximum = 65535.0},
                {.name = "type",
                 .type = F::Enum,
                 .description = "Encoding: int16 / scaled_int16 one register, int32 / "
                                "scaled_int32 / float32 two.",
                 .choices = {"int16", "int32", "scaled_int16", "scaled_int32", "float32"},
                 .defaultValue = "float32"},
                {.name = "factor",
                 .type = F::Number,
                 .description = "Scaled types hold round(value * factor), e.g. 1000 for "
                                "micrometres; required for them, refused for the others.",
                 .minimum = 0.0,
                 .exclusiveMinimum = true},
                {.name = "word_order",
                 .type = F::Enum,
                 .description = "Order of the bytes of a 32-bit value; default: the station's "
                                "plc.word_order.",
                 .choices = {"ABCD", "CDAB", "BADC", "DCBA"}}}};

  check = {"check",
           "A checked value: passes when nominal - tol_minus <= measured <= nominal + tol_plus.",
           {{.name = "nominal",
             .type = F::Number,
             .description = "Nominal value in `unit`.",
             .required = true},
            {.name = "tol_minus",
             .type = F::Number,
             .description = "Allowed deviation below nominal, >= 0.",
             .required = true,
             .minimum = 0.0},
            {.name = "tol_plus",
             .type = F::Number,
             .description = "Allowed deviation above nominal, >= 0.",
             .required = true,
             .minimum = 0.0},
            {.name = "unit",
             .type = F::Enum,
             .description = "mm or px for lengths (default mm), deg for angles; none for "
                            "counts and scores.",
             .choices = {"mm", "deg", "px"}},
            {.name = "plc",
             .type = F::Object,
             .description = "Where the measured value goes on the PLC.",
             .object = &plcOutput}}};

  const std::string xDoc = "Offset of the found position from nominal along x (mm by default).";
  const std::string yDoc = "Offset of the found position from nominal along y (mm by default).";
  checks[0] = {"align checks",
               "",
               {checkField("x", Quantity::Length, xDoc), checkField("y", Quantity::Length, yDoc),
                checkField("angle", Quantity::Angle, "Rotation of the part, degrees."),
                checkField("score", Quantity::Score, "Match score, 0..1.", 0.0)}};
  checks[1] = {
      "fiducials checks",
      "",
      {checkField("x", Quantity::Length, "Shift of the marks' centroid along x."),
       checkField("y", Quantity::Length, "Shift of the marks' centroid along y."),
       checkField("angle", Quantity::Angle, "Rotation of the marks, degrees."),
       checkField("spacing", Quantity::Length, "Distance between the first two marks.", 0.0)}};
  checks[2] = {"shape checks",
               "",
               {checkField("count", Quantity::Count, "Number of matches found.", 0.0),
                checkField("x", Quantity::Length, xDoc), checkField("y", Quantity::Length, yDoc),
                checkField("angle", Quantity::Angle, "Rotation of the best match, degrees."),
                checkField("score", Quantity::Score, "Score of the best match, 0..1.", 0.0)}};
  checks[3] = {
      "circle checks",
      "",
      {checkField("diameter", Quantity::Length, "Fitted diameter.", 0.0),
       checkField("x", Quantity::Length, "Centre offset from nominal along x."),
       checkField("y", Quantity::Length, "Centre offset from nominal along y."),
       checkField("position", Quantity::Length,
                  "Distance of the centre from its nominal position (true position).", 0.0),
       checkField("roundness", Quantity::Length,
                  "Largest minus smallest radius of the edge points.", 0.0)}};
  checks[4] = {"distance checks",
               "",
               {checkField("distance", Quantity::Length,
                           "centre_to_centre and point_to_line: the distance.", 0.0),
                checkField("angle", Quantity::Angle, "angle: the angle between the two lines.")}};
  checks[5] = {"scan_align checks",
               "",
               {checkField("x", Quantity::Length, "Offset of the scan along x."),
                checkField("y", Quantity::Length, "Offset of the scan along y."),
                checkField("angle", Quantity::Angle, "Rotation of the scan, degrees.")}};

  // Every entry of a `checks:` mapping is a checked value.
  for (auto& kindChecks : checks)
    for (auto& f : kindChecks.fields) f.object = &check;

  steps.push_back(
      {"align",
       stepObject(
           "align",
           "Finds the part and gives the pose later steps follow: log-polar registration to a "
           "reference image, or a shape match.",
           {{.name = "method",
             .type = F::Enum,
             .description = "registration (features of a reference image) or shape (a "
                            "trained shape model).",
             .required = true,
             .choices = {"registration", "shape"}},
            {.name = "reference",
             .type = F::Path,
             .description = "Reference image (registration) or template image the model is "
                            "trained from (shape), relative to the recipe.",
             .required = true},
            region("[x, y, width, height] of the reference used, pixels; default: all of it."),
            {.name = "model",
             .type = F::Path,
             .description = "Trained shape model (method shape), written by `facet recipe "
                            "train`."},
            searchRegion(),
            minScore(),
            angleRange()},
           &checks[0])});
  steps.push_back(
      {"fiducials",
       stepObject("fiducials", "Finds round marks near their nominal positions.",
                  {relativeTo(),
                   {.name = "marks",
                    .type = F::PointList,
                    .description = "Nominal mark centres [x, y], pixels; at least two.",
                    .required = true,
                    .minItems = 2},
                   {.name = "mark_diameter",
                    .type = F::Number,
                    .description = "Diameter of a mark, mm.",
                    .required = true,
                    .minimum = 0.0,
                    .exclusiveMinimum = true},
                   {.name = "search_radius",
                    .type = F::Number,
                    .description = "How far from its nominal centre a mark is searched, mm.",
                    .minimum = 0.0,
                    .exclusiveMinimum = true,
                    .defaultValue = 1.0},
                   {.name = "polarity",
                    .type = F::Enum,
                    .description = "Marks darker or lighter than their surroundings.",
                    .choices = {"dark_inside", "light_inside", "any"},
                    .defaultValue = "any"}},
                  &checks[1])});
  steps.push_back(
      {"shape",
       stepObject("shape", "Finds a trained shape model and checks count and pose.",
                  {relativeTo(),
                   {.name = "template",
                    .type = F::Path,
                    .description = "Image the model is trained from, relative to the recipe.",
                    .required = true},
                   region("[x, y, width, height] of the template that holds the part, pixels."),
                   {.name = "model",
                    .type = F::Path,
                    .description = "Trained model file, written by `facet recipe train`.",
                    .required = true},
                   searchRegion(),
                   minScore(),
                   {.name = "num_matches",
                    .type = F::Integer,
                    .description = "Most matches searched.",
                    .minimum = 1.0,
                    .maximum = 100.0,
                    .defaultValue = 1},
                   angleRange(),
                   {.name = "max_overlap",
                    .type = F::Number,
                    .description = "Largest overlap of two matches, 0..1.",
                    .minimum = 0.0,
                    .maximum = 1.0,
                    .defaultValue = 0.5}},
                  &checks[2])});
  steps.push_back(
      {"circle",
       stepObject("circle", "Measures a circle in an annulus around its nominal position.",
                  {relativeTo(),
                   {.name = "centre",
                    .type = F::Point,
                    .description = "Nominal centre [x, y], pixels of the relative_to step's "
                                   "reference image.",
                    .required = true},
                   {.name = "nominal_diameter",
                    .type = F::Number,
                    .description = "Nominal diameter, mm.",
                    .required = true,
                    .minimum = 0.0,
                    .exclusiveMinimum = true},
                   {.name = "search_width",
                    .type = F::Number,
                    .description = "Width of the annulus searched around the nominal circle, "
                                   "mm; less than the diameter.",
                    .required = true,
                    .minimum = 0.0,
                    .exclusiveMinimum = true},
                   {.name = "polarity",
                    .type = F::Enum,
                    .description = "Circle darker (a hole) or lighter than its surroundings.",
                    .choices = {"dark_inside", "light_inside", "any"},
                    .defaultValue = "any"}},
                  &checks[3])});
  steps.push_back(
      {"distance",
       stepObject("distance", "A distance or angle between the results of two earlier steps.",
                  {{.name = "measure",
                    .type = F::Enum,
                    .description = "centre_to_centre (two points), point_to_line (`from` a "
                                   "point, `to` a pose's x axis), angle (between two poses' x "
                                   "axes).",
                    .required = true,
                    .choices = {"centre_to_centre", "point_to_line", "angle"}},
                   {.name = "from",
                    .type = F::StepRef,
                    .description = "Id of an earlier step.",
                    .required = true},
                   {.name = "to",
                    .type = F::StepRef,
                    .description = "Id of an earlier step.",
                    .required = true}},
                  &checks[4])});
  steps.push_back(
      {"scan_align",
       stepObject("scan_align", "Registers a live 2D range scan to a reference scan.",
                  {{.name = "reference",
                    .type = F::Path,
                    .description = "Reference scan (CSV rows \"x,y\" in metres), relative to "
                                   "the recipe.",
                    .required = true},
                   {.name = "method",
                    .type = F::Enum,
                    .description = "icp, dcp (dual closest point) or idcp (clustered).",
                    .choices = {"icp", "dcp", "idcp"},
                    .defaultValue = "dcp"},
                   {.name = "max_iterations",
                    .type = F::Integer,
                    .description = "Iterations at most.",
                    .minimum = 1.0,
                    .maximum = 1000.0,
                    .defaultValue = 50},
                   {.name = "max_distance",
                    .type = F::Number,
                    .description = "Correspondences farther apart are ignored, mm.",
                    .minimum = 0.0,
                    .exclusiveMinimum = true,
                    .defaultValue = 5.0}},
                  &checks[5])});

  recipe = {"recipe",
            "A facet inspection recipe: what the line checks on one part type.",
            {{.name = "schema_version",
              .type = F::Integer,
              .description = "Version of this format; 1.",
              .required = true,
              .minimum = 1.0,
              .maximum = 1.0},
             {.name = "id",
              .type = F::Integer,
              .description = "Number the PLC selects the recipe by, unique in the folder.",
              .required = true,
              .minimum = 1.0,
              .maximum = 65535.0},
             {.name = "name", .type = F::String, .description = "Display name.", .required = true},
             {.name = "version", .type = F::String, .description = "Free-text version."},
             {.name = "description", .type = F::String, .description = "Free text."},
             {.name = "steps",
              .type = F::StepList,
              .description = "Steps, run in order; a step may use results of earlier steps.",
              .required = true,
              .minItems = 1}}};
}

const StepKindSpec* RecipeFormat::stepKind(std::string_view kind) const {
  for (const auto& s : steps)
    if (s.kind == kind) return &s;
  return nullptr;
}

std::vector<std::string> RecipeFormat::stepKindNames() const {
  std::vector<std::string> names;
  for (const auto& s : steps) names.push_back(s.kind);
  return names;
}

const RecipeFormat& recipeFormat() {
  static const RecipeFormat format;
  return format;
}

}  // namespace facet::config
