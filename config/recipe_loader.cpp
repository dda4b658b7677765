#include "config/recipe_loader.hpp"

#include <algorithm>
#include <fstream>
#include <map>
#include <set>

#include <opencv2/imgcodecs.hpp>

#include "algorithms/shape/shape_model_file.hpp"
#include "config/closest_name.hpp"
#include "config/confined_path.hpp"
#include "config/content_hash.hpp"
#include "config/recipe_format.hpp"
#include "config/training_record.hpp"
#include "config/yaml_document.hpp"
#include "config/yaml_validation.hpp"

namespace facet::config {
namespace {

// Non-throwing file checks: a name too long for the file system, a loop of links or a folder
// we may not read mean "not there", reported as such, never an exception out of the loader.
bool isFile(const std::filesystem::path& p) {
  std::error_code ec;
  return std::filesystem::is_regular_file(p, ec);
}

std::string inQuotes(const std::string& s) {
  return "'" + s + "'";
}

std::optional<StepKind> stepKindNamed(const std::string& name) {
  for (auto k : {StepKind::Align, StepKind::Fiducials, StepKind::Shape, StepKind::Circle,
                 StepKind::Distance, StepKind::ScanAlign})
    if (toString(k) == name) return k;
  return std::nullopt;
}

std::size_t kindIndex(StepKind kind) {
  return static_cast<std::size_t>(kind);
}

// Steps whose result has an orientation (a pose): others can follow it, lines run along it.
bool givesPose(StepKind k) {
  return k == StepKind::Align || k == StepKind::Fiducials || k == StepKind::Shape;
}
// Steps whose result has a position in the image.
bool givesPoint(StepKind k) {
  return givesPose(k) || k == StepKind::Circle;
}

CirclePolarity polarityNamed(const std::string& s) {
  if (s == "dark_inside") return CirclePolarity::DarkInside;
  if (s == "light_inside") return CirclePolarity::LightInside;
  return CirclePolarity::Any;
}

std::optional<cv::Rect2d> rectOf(const YAML::Node& n) {
  if (!n || !n.IsSequence() || n.size() != 4) return std::nullopt;
  std::array<double, 4> v{};
  for (std::size_t i = 0; i < 4; ++i) {
    const auto x = readNumber(n[i]);
    if (!x) return std::nullopt;
    v[i] = *x;
  }
  if (v[2] <= 0 || v[3] <= 0) return std::nullopt;
  return cv::Rect2d(v[0], v[1], v[2], v[3]);
}

std::optional<cv::Point2d> pointOf(const YAML::Node& n) {
  if (!n || !n.IsSequence() || n.size() != 2) return std::nullopt;
  const auto x = readNumber(n[0]), y = readNumber(n[1]);
  if (!x || !y) return std::nullopt;
  return cv::Point2d(*x, *y);
}

AngleRange angleRangeOf(const YAML::Node& n) {
  AngleRange r;
  if (n && n.IsSequence() && n.size() == 2) {
    r.low = readNumber(n[0]).value_or(r.low);
    r.high = readNumber(n[1]).value_or(r.high);
  }
  return r;
}

// Reads one recipe file; every method adds what it finds wrong to `out_`.
class RecipeReader {
 public:
  RecipeReader(const std::filesystem::path& file, const RecipeLoadOptions& options,
               Diagnostics& out)
      : file_(file), options_(options), out_(out) {
    recipe_.file = std::filesystem::absolute(file).lexically_normal();
    recipe_.baseFolder = recipe_.file.parent_path();
    root_ = options.root ? std::filesystem::absolute(*options.root) : recipe_.baseFolder;
  }

  [[nodiscard]] int id() const { return recipe_.id; }
  [[nodiscard]] const SourceLocation& idWhere() const { return recipe_.idWhere; }

  // Every file looked at so far (valid after read(), also when it failed).
  std::vector<std::filesystem::path> files() const {
    std::vector<std::filesystem::path> all{recipe_.file};
    all.insert(all.end(), recipe_.dependencies.begin(), recipe_.dependencies.end());
    return all;
  }

  std::optional<Recipe> read() {
    const auto yaml = readYamlFile(file_, out_);
    if (!yaml) return std::nullopt;
    const RecipeFormat& format = recipeFormat();
    validateObject(yaml->root, format.recipe, file_, out_, format.steps);
    recipe_.contentHash = hexHash(fnv1a64(yaml->bytes));
    const YAML::Node& root = yaml->root;
    if (!root.IsMap()) return std::nullopt;

    recipe_.schemaVersion = static_cast<int>(readInteger(root["schema_version"]).value_or(0));
    recipe_.id = static_cast<int>(readInteger(root["id"]).value_or(0));
    if (root["id"]) recipe_.idWhere = where(root["id"]);
    recipe_.name = text(root["name"]);
    recipe_.version = text(root["version"]);
    recipe_.description = text(root["description"]);

    const YAML::Node steps = root["steps"];
    if (steps && steps.IsSequence()) {
      collectStepIds(steps);
      for (const auto& item : steps) readStep(item);
    }
    checkRegisterCollisions(registerUses(), out_);
    if (out_.hasErrors()) return std::nullopt;
    return recipe_;
  }

 private:
  static std::string text(const YAML::Node& n) { return n ? readString(n).value_or("") : ""; }

  SourceLocation where(const YAML::Node& n) const { return locate(file_, n); }
  void error(const YAML::Node& n, std::string message) { out_.error(where(n), std::move(message)); }

  void collectStepIds(const YAML::Node& steps) {
    for (const auto& item : steps) {
      if (!item.IsMap() || !item["id"] || !item["id"].IsScalar()) continue;
      allIds_.emplace(item["id"].Scalar(), where(item["id"]).line);  // keeps the first
    }
  }

  void readStep(const YAML::Node& item) {
    if (!item.IsMap() || !item["kind"] || !item["kind"].IsScalar()) return;
    const auto kind = stepKindNamed(item["kind"].Scalar());
    if (!kind) {  // reported by the validator; references to it are not errors of their own
      if (item["id"] && item["id"].IsScalar()) unknownKindIds_.insert(item["id"].Scalar());
      return;
    }
    Step step;
    step.kind = *kind;
    step.where = where(item);
    step.id = text(item["id"]);
    step.name = item["name"] ? text(item["name"]) : step.id;
    if (!step.id.empty()) {
      if (const auto it = earlier_.find(step.id); it != earlier_.end())
        error(item["id"], "duplicate step id " + inQuotes(step.id) + " (first used at line " +
                              std::to_string(it->second.where.line) + ")");
    }
    switch (step.kind) {
      case StepKind::Align:
        step.params = readAlign(item);
        break;
      case StepKind::Fiducials:
        step.params = readFiducials(item);
        break;
      case StepKind::Shape:
        step.params = readShape(item);
        break;
      case StepKind::Circle:
        step.params = readCircle(item);
        break;
      case StepKind::Distance:
        step.params = readDistance(item);
        break;
      case StepKind::ScanAlign:
        step.params = readScanAlign(item);
        break;
    }
    readChecks(item["checks"], step);
    if (step.kind == StepKind::Align || step.kind == StepKind::Shape) checkModel(item, step);
    if (!step.id.empty() && !earlier_.contains(step.id))
      earlier_.emplace(step.id, EarlierStep{step.kind, step.where});
    recipe_.steps.push_back(std::move(step));
  }

  // A reference to an earlier step; `need` tells what its result must offer.
  enum class Need { Pose, Point };
  std::optional<std::string> stepRef(const YAML::Node& n, Need need, const std::string& key) {
    if (!n || !n.IsScalar()) return std::nullopt;
    const std::string id = n.Scalar();
    if (unknownKindIds_.contains(id)) return id;  // one error per cause: the unknown kind
    const auto it = earlier_.find(id);
    if (it == earlier_.end()) {
      if (const auto later = allIds_.find(id); later != allIds_.end()) {
        error(n, inQuotes(key) + " refers to step " + inQuotes(id) + ", which comes later (line " +
                     std::to_string(later->second) + "); a step may only use earlier steps");
      } else {
        std::vector<std::string> ids;
        for (const auto& [name, line] : allIds_) ids.push_back(name);
        std::string message = inQuotes(key) + " refers to unknown step " + inQuotes(id);
        if (const auto near = closestName(id, ids))
          message += " (did you mean " + inQuotes(*near) + "?)";
        error(n, message);
      }
      return id;
    }
    const StepKind k = it->second.kind;
    if (need == Need::Pose && !givesPose(k))
      error(n, inQuotes(key) + " needs a step that gives a pose (align, fiducials or shape), but " +
                   inQuotes(id) + " is a " + std::string(toString(k)) + " step");
    if (need == Need::Point && !givesPoint(k))
      error(n, inQuotes(key) +
                   " needs a step that gives a position (align, fiducials, shape or "
                   "circle), but " +
                   inQuotes(id) + " is a " + std::string(toString(k)) + " step");
    return id;
  }

  enum class FileKind { Image, Scan, Model };
  // Resolves a path inside the recipes folder; checks existence and content of images and scans.
  std::optional<std::filesystem::path> file(const YAML::Node& n, const std::string& key,
                                            FileKind kind) {
    if (!n || !n.IsScalar() || n.Scalar().empty()) return std::nullopt;
    const auto resolved = confinedPath(n.Scalar(), recipe_.baseFolder, root_);
    if (const auto* problem = std::get_if<std::string>(&resolved)) {
      error(n, inQuotes(key) + " path " + inQuotes(n.Scalar()) + " " + *problem);
      return std::nullopt;
    }
    const auto& path = std::get<std::filesystem::path>(resolved);
    recipe_.dependencies.push_back(path);
    if (kind == FileKind::Model) {
      recipe_.dependencies.push_back(trainingRecordPath(path));
      return path;  // checked against its training record by checkModel
    }
    if (!isFile(path)) {
      error(n, inQuotes(key) + " file " + inQuotes(n.Scalar()) + " does not exist (looked for " +
                   path.string() + ")");
      return std::nullopt;
    }
    if (kind == FileKind::Image) {
      const cv::Mat image = cv::imread(path.string(), cv::IMREAD_UNCHANGED);
      if (image.empty())
        error(n, inQuotes(key) + " file " + inQuotes(n.Scalar()) + " cannot be read as an image");
      else
        imageSizes_[path] = image.size();
    } else {
      checkScanFile(n, path);
    }
    return path;
  }

  void checkScanFile(const YAML::Node& n, const std::filesystem::path& path) {
    std::ifstream in(path);
    std::string line;
    int lineNo = 0, points = 0;
    while (std::getline(in, line)) {
      ++lineNo;
      if (line.empty() || line[0] == '#') continue;
      std::vector<double> values;
      std::size_t start = 0;
      bool numeric = true;
      while (start <= line.size()) {
        const std::size_t comma = std::min(line.find(',', start), line.size());
        YAML::Node cell(line.substr(start, comma - start));
        const auto v = readNumber(cell);
        numeric = numeric && v.has_value();
        values.push_back(v.value_or(0));
        start = comma + 1;
      }
      if (!numeric && lineNo == 1) continue;  // a header
      if (!numeric || (values.size() != 2 && values.size() != 3)) {
        out_.error({path, lineNo, 1}, "expected a point \"x,y\" in metres (or \"scan,x,y\")");
        return;
      }
      ++points;
    }
    if (points < 3)
      error(n, "reference scan " + inQuotes(n.Scalar()) + " has " + std::to_string(points) +
                   " points; at least 3 are needed");
  }

  void checkRegion(const YAML::Node& regionNode, const std::optional<std::filesystem::path>& image,
                   const std::string& imageKey) {
    const auto region = rectOf(regionNode);
    if (!region || !image || !imageSizes_.contains(*image)) return;
    const cv::Size size = imageSizes_[*image];
    if (region->x < 0 || region->y < 0 || region->x + region->width > size.width ||
        region->y + region->height > size.height)
      error(regionNode, "'region' reaches outside the " + imageKey + " image (" +
                            std::to_string(size.width) + "x" + std::to_string(size.height) +
                            " pixels)");
  }

  AlignStep readAlign(const YAML::Node& item) {
    AlignStep a;
    a.method = text(item["method"]) == "shape" ? AlignStep::Method::Shape
                                               : AlignStep::Method::Registration;
    const auto reference = file(item["reference"], "reference", FileKind::Image);
    a.reference = reference.value_or(std::filesystem::path{});
    a.region = rectOf(item["region"]);
    checkRegion(item["region"], reference, "reference");
    if (item["model"]) {
      if (a.method != AlignStep::Method::Shape)
        out_.warning(where(item["model"]), "'model' is only used with method shape");
      a.model = file(item["model"], "model", FileKind::Model);
    } else if (a.method == AlignStep::Method::Shape && item["method"]) {
      error(item["method"], "method shape needs a 'model' file (written by `facet recipe train`)");
    }
    a.searchRegion = rectOf(item["search_region"]);
    a.minScore = readNumber(item["min_score"]).value_or(a.minScore);
    a.angleRange = angleRangeOf(item["angle_range"]);
    return a;
  }

  FiducialsStep readFiducials(const YAML::Node& item) {
    FiducialsStep f;
    if (item["relative_to"]) f.relativeTo = stepRef(item["relative_to"], Need::Pose, "relative_to");
    if (const YAML::Node marks = item["marks"]; marks && marks.IsSequence())
      for (const auto& m : marks)
        if (const auto p = pointOf(m)) f.marks.push_back(*p);
    f.markDiameter = readNumber(item["mark_diameter"]).value_or(f.markDiameter);
    f.searchRadius = readNumber(item["search_radius"]).value_or(f.searchRadius);
    f.polarity = polarityNamed(text(item["polarity"]));
    for (std::size_t i = 0; i < f.marks.size(); ++i)
      for (std::size_t j = 0; j < i; ++j)
        if (cv::norm(f.marks[i] - f.marks[j]) < 1e-9)
          error(item["marks"][i],
                "mark " + std::to_string(i + 1) + " lies on mark " + std::to_string(j + 1));
    return f;
  }

  ShapeStep readShape(const YAML::Node& item) {
    ShapeStep s;
    if (item["relative_to"]) s.relativeTo = stepRef(item["relative_to"], Need::Pose, "relative_to");
    const auto image = file(item["template"], "template", FileKind::Image);
    s.templateImage = image.value_or(std::filesystem::path{});
    s.region = rectOf(item["region"]);
    checkRegion(item["region"], image, "template");
    s.model = file(item["model"], "model", FileKind::Model).value_or(std::filesystem::path{});
    s.searchRegion = rectOf(item["search_region"]);
    s.minScore = readNumber(item["min_score"]).value_or(s.minScore);
    s.numMatches = static_cast<int>(readInteger(item["num_matches"]).value_or(s.numMatches));
    s.angleRange = angleRangeOf(item["angle_range"]);
    s.maxOverlap = readNumber(item["max_overlap"]).value_or(s.maxOverlap);
    return s;
  }

  CircleStep readCircle(const YAML::Node& item) {
    CircleStep c;
    if (item["relative_to"]) c.relativeTo = stepRef(item["relative_to"], Need::Pose, "relative_to");
    c.centre = pointOf(item["centre"]).value_or(c.centre);
    c.nominalDiameter = readNumber(item["nominal_diameter"]).value_or(0.0);
    c.searchWidth = readNumber(item["search_width"]).value_or(0.0);
    c.polarity = polarityNamed(text(item["polarity"]));
    if (c.nominalDiameter > 0 && c.searchWidth >= c.nominalDiameter)
      error(item["search_width"], "'search_width' " + formatNumber(c.searchWidth) +
                                      " mm must be smaller than 'nominal_diameter' " +
                                      formatNumber(c.nominalDiameter) +
                                      " mm: the search annulus would cover the centre");
    return c;
  }

  DistanceStep readDistance(const YAML::Node& item) {
    DistanceStep d;
    const std::string measure = text(item["measure"]);
    d.measure = measure == "angle"           ? DistanceStep::Measure::Angle
                : measure == "point_to_line" ? DistanceStep::Measure::PointToLine
                                             : DistanceStep::Measure::CentreToCentre;
    const Need fromNeed = d.measure == DistanceStep::Measure::Angle ? Need::Pose : Need::Point;
    const Need toNeed =
        d.measure == DistanceStep::Measure::CentreToCentre ? Need::Point : Need::Pose;
    d.from = stepRef(item["from"], fromNeed, "from").value_or("");
    d.to = stepRef(item["to"], toNeed, "to").value_or("");
    if (!d.from.empty() && d.from == d.to)
      error(item["to"], "'from' and 'to' are the same step " + inQuotes(d.to));
    // The check must be the quantity the measure gives.
    if (const YAML::Node checks = item["checks"]; checks && checks.IsMap() && item["measure"]) {
      const std::string wanted = d.measure == DistanceStep::Measure::Angle ? "angle" : "distance";
      for (const auto& entry : checks) {
        const std::string name = entry.first.Scalar();
        if ((name == "angle" || name == "distance") && name != wanted)
          error(entry.first, "check " + inQuotes(name) + " does not fit measure " +
                                 inQuotes(measure) + "; use " + inQuotes(wanted));
      }
    }
    return d;
  }

  ScanAlignStep readScanAlign(const YAML::Node& item) {
    ScanAlignStep s;
    s.reference =
        file(item["reference"], "reference", FileKind::Scan).value_or(std::filesystem::path{});
    const std::string method = text(item["method"]);
    s.method = method == "icp"    ? ScanAlignStep::Method::Icp
               : method == "idcp" ? ScanAlignStep::Method::Idcp
                                  : ScanAlignStep::Method::Dcp;
    s.maxIterations =
        static_cast<int>(readInteger(item["max_iterations"]).value_or(s.maxIterations));
    s.maxDistance = readNumber(item["max_distance"]).value_or(s.maxDistance);
    return s;
  }

  void readChecks(const YAML::Node& checks, Step& step) {
    if (!checks || !checks.IsMap()) return;
    const ObjectSpec& table = recipeFormat().checks[kindIndex(step.kind)];
    for (const auto& entry : checks) {
      const FieldSpec* field = entry.first.IsScalar() ? table.find(entry.first.Scalar()) : nullptr;
      if (!field || !entry.second.IsMap()) continue;  // reported by the validator
      if (step.check(field->name)) continue;          // duplicate key, reported
      if (auto check = readCheck(entry.first, entry.second, *field, step)) {
        step.checks.push_back(std::move(*check));
      }
    }
  }

  std::optional<Check> readCheck(const YAML::Node& key, const YAML::Node& node,
                                 const FieldSpec& field, const Step& step) {
    Check c;
    c.name = field.name;
    c.quantity = *field.quantity;
    c.where = where(key);
    const auto nominal = readNumber(node["nominal"]);
    const auto tolMinus = readNumber(node["tol_minus"]);
    const auto tolPlus = readNumber(node["tol_plus"]);
    const std::string label = inQuotes(step.id + "." + c.name);

    // Units follow the quantity.
    const std::string unit = text(node["unit"]);
    switch (c.quantity) {
      case Quantity::Length:
        c.unit = unit == "px" ? Unit::Pixel : Unit::Millimetre;
        if (unit == "deg")
          error(node["unit"], label + " is a length: its unit is mm or px, not deg");
        break;
      case Quantity::Angle:
        c.unit = Unit::Degree;
        if (!unit.empty() && unit != "deg")
          error(node["unit"], label + " is an angle: its unit is deg, not " + unit);
        break;
      case Quantity::Count:
      case Quantity::Score:
        c.unit = Unit::None;
        if (!unit.empty())
          error(node["unit"], label + " is a " +
                                  (c.quantity == Quantity::Count ? "count" : "score") +
                                  " and has no unit");
        break;
    }

    if (nominal && field.minimum && *nominal < *field.minimum)
      error(node["nominal"], "nominal " + formatNumber(*nominal) + " of " + label + " is below " +
                                 formatNumber(*field.minimum) + ", which it can never be");
    else if (nominal && tolMinus && field.minimum && *nominal - *tolMinus < *field.minimum)
      error(node["tol_minus"], "tol_minus " + formatNumber(*tolMinus) + " of " + label +
                                   " is larger than its nominal " + formatNumber(*nominal) +
                                   " allows: the lower limit " +
                                   formatNumber(*nominal - *tolMinus) + " is below " +
                                   formatNumber(*field.minimum));
    if (c.quantity == Quantity::Score && nominal && *nominal > 1)
      error(node["nominal"],
            "nominal " + formatNumber(*nominal) + " of " + label + " is above 1, the best score");
    if (c.quantity == Quantity::Count && nominal && *nominal != std::floor(*nominal))
      error(node["nominal"],
            "nominal " + formatNumber(*nominal) + " of " + label + " must be a whole number");
    if (tolMinus && tolPlus && *tolMinus == 0 && *tolPlus == 0 && c.quantity != Quantity::Count)
      out_.warning(where(node["tol_minus"]), label + " has no tolerance: only exactly " +
                                                 formatNumber(nominal.value_or(0)) + " passes");

    c.nominal = nominal.value_or(0);
    c.tolMinus = tolMinus.value_or(0);
    c.tolPlus = tolPlus.value_or(0);
    if (const YAML::Node plc = node["plc"]; plc && plc.IsMap()) readPlcOutput(plc, step, c);
    return c;
  }

  void readPlcOutput(const YAML::Node& plc, const Step& step, Check& c) {
    const auto address = readInteger(plc["register"]);
    if (!address) return;
    PlcOutput out;
    out.where = where(plc["register"]);
    out.output.name = step.id + "." + c.name;
    out.output.address = static_cast<int>(*address);
    out.output.origin = format(out.where);
    out.output.wordOrder = options_.defaultWordOrder;
    if (plc["type"])
      if (const auto type = plc::parseValueType(text(plc["type"]))) out.output.type = *type;
    if (plc["word_order"])
      if (const auto order = plc::parseWordOrder(text(plc["word_order"])))
        out.output.wordOrder = *order;
    const bool scaled = out.output.type == plc::ValueType::ScaledInt16 ||
                        out.output.type == plc::ValueType::ScaledInt32;
    if (const auto factor = readNumber(plc["factor"])) {
      out.output.factor = *factor;
      if (!scaled)
        error(plc["factor"], "'factor' applies to scaled_int16 and scaled_int32 only, not " +
                                 plc::toString(out.output.type));
    } else if (scaled && !plc["factor"]) {
      error(plc["type"], "type " + plc::toString(out.output.type) + " needs a 'factor'");
    }
    uses_.push_back({out.output.name, out.output.address, out.words(), out.where});
    c.plc = out;
  }

  void checkModel(const YAML::Node& item, const Step& step) {
    std::optional<std::filesystem::path> model, source;
    if (const auto* a = std::get_if<AlignStep>(&step.params)) {
      if (a->method != AlignStep::Method::Shape) return;
      model = a->model, source = a->reference;
    } else {
      const auto& s = std::get<ShapeStep>(step.params);
      if (!s.model.empty()) model = s.model;
      source = s.templateImage;
    }
    if (!model || !source || source->empty() || !options_.requireTrainedModels) return;
    const ModelStatus status = modelStatus(*model, *source, trainingParameters(step));
    const std::string advice = "; run `facet recipe train " + file_.string() + "`";
    const std::string what = "model " + inQuotes(item["model"].Scalar()) + " ";
    // A file that is no model at all (or one of another facet version) is that, not "stale".
    if (status.state != ModelState::Missing) {
      try {
        loadShapeModel(*model);
      } catch (const std::exception& e) {
        error(item["model"], what + "cannot be loaded: " + e.what() + advice);
        return;
      }
    }
    switch (status.state) {
      case ModelState::Fresh:
        break;
      case ModelState::Untracked:
        out_.warning(where(item["model"]),
                     what + status.detail + ", so staleness is unknown" + advice);
        break;
      case ModelState::Missing:
      case ModelState::Stale:
        error(item["model"], what + (status.state == ModelState::Missing ? "" : "is stale: ") +
                                 status.detail + advice);
        break;
    }
  }

  std::vector<RegisterUse> registerUses() const {
    std::vector<RegisterUse> all = options_.reservedRegisters;
    for (auto& r : all) r.reserved = true;
    all.insert(all.end(), uses_.begin(), uses_.end());
    return all;
  }

  struct EarlierStep {
    StepKind kind;
    SourceLocation where;
  };

  const std::filesystem::path& file_;
  const RecipeLoadOptions& options_;
  Diagnostics& out_;
  std::filesystem::path root_;
  Recipe recipe_;
  std::map<std::string, EarlierStep> earlier_;  // ids of the steps read so far
  std::map<std::string, int> allIds_;           // every step id -> its line
  std::set<std::string> unknownKindIds_;        // steps whose kind is unknown (already an error)
  std::map<std::filesystem::path, cv::Size> imageSizes_;
  std::vector<RegisterUse> uses_;
};

std::string span(const RegisterUse& u) {
  return u.words == 1 ? std::to_string(u.address)
                      : std::to_string(u.address) + "-" + std::to_string(u.address + u.words - 1);
}

}  // namespace

void checkRegisterCollisions(const std::vector<RegisterUse>& uses, Diagnostics& out) {
  for (std::size_t i = 0; i < uses.size(); ++i) {
    const RegisterUse& b = uses[i];
    if (b.reserved) continue;
    if (b.address + b.words - 1 > 65535)
      out.error(b.where, "register " + span(b) + " of " + inQuotes(b.owner) +
                             " runs past the last register 65535");
    for (std::size_t j = 0; j < i; ++j) {
      const RegisterUse& a = uses[j];
      const bool overlap = b.address < a.address + a.words && a.address < b.address + b.words;
      if (!overlap) continue;
      std::string other = inQuotes(a.owner) + " (registers " + span(a);
      if (a.where.line > 0)
        other +=
            ", " +
            (a.where.file == b.where.file ? std::string("line ") : a.where.file.string() + ":") +
            std::to_string(a.where.line);
      out.error(b.where, "register " + span(b) + " of " + inQuotes(b.owner) + " collides with " +
                             other + ")");
    }
  }
}

RecipeLoadResult loadRecipe(const std::filesystem::path& file, const RecipeLoadOptions& options) {
  RecipeLoadResult result;
  RecipeReader reader(file, options, result.diagnostics);
  result.recipe = reader.read();
  result.files = reader.files();
  result.id = reader.id();
  result.idWhere = reader.idWhere();
  return result;
}

}  // namespace facet::config
