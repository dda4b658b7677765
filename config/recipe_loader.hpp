#pragma once
// Reading one recipe file: YAML -> validated Recipe, or every problem found, each with its file,
// line and column. A recipe with an error is never returned, so a half-valid recipe can never be
// applied.

#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include "config/diagnostic.hpp"
#include "config/recipe.hpp"
#include "config/step_kind.hpp"

namespace facet::config {

// Holding registers someone writes: a recipe's check output, or one the station reserves.
struct RegisterUse {
  std::string owner;  // "hole.diameter", or "station result.verdict"
  int address = 0;
  int words = 1;
  SourceLocation where;
  bool reserved = false;  // the station's own; collisions are reported at the other use
};

struct RecipeLoadOptions {
  // Folder every path in the recipe must stay inside. Default: the recipe file's folder.
  std::optional<std::filesystem::path> root;
  // Registers the station already uses (handshake, verdict): recipe outputs may not overlap them.
  std::vector<RegisterUse> reservedRegisters;
  // Missing or stale shape models are errors (off while `facet recipe train` reads the recipe).
  bool requireTrainedModels = true;
  // Word order of 32-bit PLC outputs that do not name their own (the station's plc.word_order).
  plc::WordOrder defaultWordOrder = plc::WordOrder::ABCD;
};

struct RecipeLoadResult {
  std::optional<Recipe> recipe;  // set exactly when diagnostics has no error
  Diagnostics diagnostics;       // errors and warnings, in file order
  // The recipe file and every file it names that lies inside the root, absolute, also when the
  // recipe has errors: a change to any of them is a reason to load it again.
  std::vector<std::filesystem::path> files;
  // The recipe's id and where it is written, also when the recipe has errors (0 when unreadable),
  // so that duplicate ids across a folder can be reported in the same run.
  int id = 0;
  SourceLocation idWhere;
};

// Reads, validates and prepares (step_kind.hpp) the recipe; its steps are of the kinds in `kinds`.
RecipeLoadResult loadRecipe(const std::filesystem::path& file, const StepKindRegistry& kinds,
                            const RecipeLoadOptions& options = {});

// Reports every pair of overlapping register uses once, at the later non-reserved one, and uses
// that run past register 65535.
void checkRegisterCollisions(const std::vector<RegisterUse>& uses, Diagnostics& out);

}  // namespace facet::config
