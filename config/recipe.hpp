#pragma once
// A recipe in memory: what the line inspects for one part type, as validated by loadRecipe()
// (recipe_loader.hpp). Recipes are immutable once loaded; the daemon holds them through
// shared_ptr<const Recipe> (recipe_library.hpp) and switches between them only between parts.
//
// Units: image positions (centre, marks, regions) are pixels; lengths of the part (diameters,
// search widths, distances) are millimetres and become pixels through the station's calibration;
// angles are degrees. A check's `unit` says how its measured value is expressed.
//
// What the steps give and how later steps use it (the contract for the recipe engine):
// - Every step with a pose (align, fiducials, shape) maps positions written in its frame into
//   the live image. The frame of an align step is its reference image's pixels: registration
//   gives the similarity reference -> live; a shape match gives the model pose, applied to
//   p - r where r is the model's reference point in reference pixels (the centre of `region`,
//   or of the whole template). The frame of a fiducials step is that of its nominal `marks`
//   (its relative_to step's frame, or the live image's pixels without one); its pose is the
//   similarity that takes the nominal marks onto the found ones.
// - A step with `relative_to` writes its positions (circle centre, search regions) in that
//   step's frame, and its angle range is relative to that step's angle. Without `relative_to`
//   they are pixels of the live image.
// - Position checks (x, y, position) are offsets from nominal in millimetres along the axes of
//   the relative_to step's frame (of the live image without one).
// - For `distance`: the point of a step is the image of its reference point (align: the centre
//   of its region, r for method shape; shape: r of the best match), the circle's centre, or the
//   centroid of the found marks (fiducials); the line of a pose step runs through its point
//   along its x axis.
// - scan_align reports the pose that takes the live scan onto the reference scan's frame; its x
//   and y checks are millimetres, angle degrees.

#include <filesystem>
#include <memory>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include <opencv2/core/types.hpp>

#include "config/diagnostic.hpp"
#include "config/field_spec.hpp"
#include "config/step_kind.hpp"
#include "plc/register_map.hpp"

namespace facet::config {

inline constexpr int kRecipeSchemaVersion = 1;

enum class Unit { Millimetre, Degree, Pixel, None };

// Where a checked value goes on the PLC. `output` is the PLC module's own description (name
// "<step id>.<check name>", holding register counted like the station's register map, encoding,
// word order), ready to be added to the station's RegisterMap::results.
struct PlcOutput {
  plc::ResultOutput output;
  SourceLocation where;  // of the `register:` value

  // Holding registers the value occupies (1 or 2).
  [[nodiscard]] int words() const { return plc::registerCount(output.type); }
};

// One checked value: passes when nominal - tolMinus <= measured <= nominal + tolPlus.
struct Check {
  std::string name;  // "diameter", "x", "angle", ...
  Quantity quantity = Quantity::Length;
  double nominal = 0.0;
  double tolMinus = 0.0;  // >= 0
  double tolPlus = 0.0;   // >= 0
  Unit unit = Unit::Millimetre;
  std::optional<PlcOutput> plc;
  SourceLocation where;

  [[nodiscard]] double lower() const { return nominal - tolMinus; }
  [[nodiscard]] double upper() const { return nominal + tolPlus; }
  [[nodiscard]] bool passes(double measured) const {
    return measured >= lower() && measured <= upper();
  }
};

// One step of a recipe: the keys every step has, and its kind's own parameters and resources.
struct Step {
  std::string id;                                  // unique within the recipe
  std::string name;                                // for people; defaults to the id
  const StepKind* kind = nullptr;                  // from the registry the recipe was read with
  std::shared_ptr<const StepParams> params;        // the kind's keys, as read (never null)
  std::shared_ptr<const StepResources> resources;  // what the kind prepared (null: needs none)
  std::vector<std::string> inputs;                 // ids of the earlier steps whose results it uses
  std::vector<Check> checks;                       // in file order
  SourceLocation where;

  [[nodiscard]] std::string_view kindName() const { return kind->name(); }
  [[nodiscard]] const Check* check(std::string_view checkName) const;
  // The kind's own parameters and resources; a wrong type is a programming error (bad_cast).
  template <class P>
  [[nodiscard]] const P& as() const {
    return dynamic_cast<const P&>(*params);
  }
  template <class R>
  [[nodiscard]] const R& resourcesAs() const {
    return dynamic_cast<const R&>(*resources);
  }
};

struct Recipe {
  int schemaVersion = kRecipeSchemaVersion;
  int id = 0;  // what the PLC selects, 1..65535
  std::string name;
  std::string description;
  std::string version;               // free text from the file (may be empty)
  std::string contentHash;           // FNV-1a 64 of the recipe file's bytes, 16 hex digits
  SourceLocation idWhere;            // of the `id:` value, for messages about duplicate ids
  std::filesystem::path file;        // the recipe file
  std::filesystem::path baseFolder;  // folder its relative paths start from
  std::vector<Step> steps;           // in execution order
  // Every other file the recipe reads (images, models, scans), absolute; a change to one of them
  // changes the recipe.
  std::vector<std::filesystem::path> dependencies;

  [[nodiscard]] const Step* step(std::string_view stepId) const;
  // Every PLC output of the recipe's checks, in file order.
  [[nodiscard]] std::vector<std::pair<const Check*, const Step*>> plcOutputs() const;
};

std::string_view toString(Unit unit);

}  // namespace facet::config
