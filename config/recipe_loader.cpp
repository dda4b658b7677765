#include "config/recipe_loader.hpp"

#include <map>

#include "config/content_hash.hpp"
#include "config/recipe_format.hpp"
#include "config/step_reading.hpp"
#include "config/yaml_document.hpp"
#include "config/yaml_validation.hpp"

namespace facet::config {
namespace {

std::string inQuotes(const std::string& s) {
  return "'" + s + "'";
}

// Reads one recipe file; every method adds what it finds wrong to `out_`.
class RecipeReader {
 public:
  RecipeReader(const std::filesystem::path& file, const StepKindRegistry& kinds,
               const RecipeLoadOptions& options, Diagnostics& out)
      : file_(file), kinds_(kinds), options_(options), out_(out) {
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
    const RecipeFormat format(kinds_);
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
    Step step;
    step.kind = kinds_.find(item["kind"].Scalar());
    step.where = where(item);
    step.id = text(item["id"]);
    step.name = item["name"] ? text(item["name"]) : step.id;
    if (!step.id.empty())
      if (const auto it = earlier_.find(step.id); it != earlier_.end())
        error(item["id"], "duplicate step id " + inQuotes(step.id) + " (first used at line " +
                              std::to_string(it->second.where.line) + ")");
    // A step of an unknown kind (reported by the validator) is still an earlier step for the
    // steps after it: a reference to it gets no second message.
    const auto known = [&] {
      if (!step.id.empty())
        earlier_.emplace(step.id, StepReading::EarlierStep{step.kind, step.where});
    };
    if (step.kind == nullptr) return known();
    StepReading in(item, file_, recipe_.baseFolder, root_, options_, kinds_, earlier_, allIds_,
                   out_);
    step.params = step.kind->read(in);
    step.inputs = in.inputs();
    readChecks(item["checks"], step);
    if (!in.hasErrors()) step.resources = step.kind->prepare(step, in);
    recipe_.dependencies.insert(recipe_.dependencies.end(), in.dependencies().begin(),
                                in.dependencies().end());
    known();
    recipe_.steps.push_back(std::move(step));
  }

  void readChecks(const YAML::Node& checks, Step& step) {
    if (!checks || !checks.IsMap()) return;
    const FieldSpec* checksField = step.kind->format().object.find("checks");
    if (!checksField || !checksField->object) return;
    const ObjectSpec& table = *checksField->object;
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
      case Quantity::Area:
        c.unit = unit == "px" ? Unit::Pixel : Unit::Millimetre;
        if (unit == "deg")
          error(node["unit"], label + " is a" +
                                  (c.quantity == Quantity::Area ? "n area" : " length") +
                                  ": its unit is mm or px, not deg");
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

  std::vector<RegisterUse> registerUses() const {
    std::vector<RegisterUse> all = options_.reservedRegisters;
    for (auto& r : all) r.reserved = true;
    all.insert(all.end(), uses_.begin(), uses_.end());
    return all;
  }

  const std::filesystem::path& file_;
  const StepKindRegistry& kinds_;
  const RecipeLoadOptions& options_;
  Diagnostics& out_;
  std::filesystem::path root_;
  Recipe recipe_;
  std::map<std::string, StepReading::EarlierStep> earlier_;  // the steps read so far, by id
  std::map<std::string, int> allIds_;                        // every step id -> its line
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

RecipeLoadResult loadRecipe(const std::filesystem::path& file, const StepKindRegistry& kinds,
                            const RecipeLoadOptions& options) {
  RecipeLoadResult result;
  RecipeReader reader(file, kinds, options, result.diagnostics);
  result.recipe = reader.read();
  result.files = reader.files();
  result.id = reader.id();
  result.idWhere = reader.idWhere();
  return result;
}

}  // namespace facet::config
