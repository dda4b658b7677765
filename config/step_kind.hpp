#pragma once
// StepKind: what the recipe reader needs of one kind of step (`kind: circle`, `kind: align`, ...).
// A kind describes its keys as a table (validation, JSON schema and defaults come from it), reads
// them into its own parameters, and prepares the files it needs (images, models, scans) once, when
// the recipe is loaded: the loader's checks and the inspection use the very same resources.
//
// config/ only knows this interface. The kinds themselves live with the inspection engine
// (service/engine/steps/), which adds what a kind does on a part; the engine hands its registry to
// the loader (StepKindRegistry below). config never includes a step kind.

#include <filesystem>
#include <memory>
#include <string>
#include <string_view>
#include <vector>

#include "config/field_spec.hpp"

namespace facet::config {

struct Step;
class StepReading;

// A kind's parameters as read from the file; each kind derives its own struct.
struct StepParams {
  virtual ~StepParams() = default;
};

// What a kind's prepare() loaded for one step (reference image, shape model, reference scan).
// Immutable once prepared: several inspections may use it at once.
struct StepResources {
  virtual ~StepResources() = default;
};

// What a step's result offers the steps after it.
struct StepOffers {
  bool point = false;  // a position in the live image (distance, point_to_line)
  bool pose = false;   // a frame later steps' positions follow (relative_to)
  bool line = false;   // a line (point_to_line, angle)
};

// A shape model written by `facet recipe train`.
struct TrainedModel {
  std::string stepId;
  std::filesystem::path model;  // absolute
  int numLevels = 0;            // pyramid levels of the model
  std::size_t points = 0;       // model points on level 0
};

class StepKind {
 public:
  virtual ~StepKind() = default;

  // The kind's name, description, keys and checks. Keys every step has (id, kind, name, checks)
  // are part of it (see stepFormat() in recipe_format.hpp).
  [[nodiscard]] virtual const StepKindSpec& format() const = 0;
  [[nodiscard]] std::string_view name() const { return format().kind; }
  [[nodiscard]] virtual StepOffers offers() const = 0;

  // Reads the kind's own keys (the validator has checked them against format() already) and
  // reports what the table cannot say (a value that contradicts another). Never null.
  [[nodiscard]] virtual std::shared_ptr<const StepParams> read(StepReading& in) const = 0;

  // Loads and checks the files the step uses; problems are reported at the key that names the
  // file. Null when the kind needs no files. Called only when read() reported no error.
  [[nodiscard]] virtual std::shared_ptr<const StepResources> prepare(const Step& step,
                                                                     StepReading& in) const;

  // Trains the step's model, when the kind has one (`facet recipe train`). Throws
  // TrainingError (recipe_training.hpp) naming the step and file.
  [[nodiscard]] virtual std::vector<TrainedModel> train(const Step& step) const;
};

// The step kinds a recipe may use, by name, in the order they were added (the order of the
// JSON schema and of "one of ..." messages).
class StepKindRegistry {
 public:
  StepKindRegistry() = default;
  StepKindRegistry(StepKindRegistry&&) = default;
  StepKindRegistry& operator=(StepKindRegistry&&) = default;

  // Throws std::logic_error when a kind of that name is registered already.
  void add(std::unique_ptr<StepKind> kind);
  [[nodiscard]] const StepKind* find(std::string_view name) const;
  [[nodiscard]] std::vector<const StepKind*> kinds() const;
  [[nodiscard]] std::vector<std::string> names() const;
  // The kinds' tables, for the validator and the JSON schema.
  [[nodiscard]] std::vector<StepKindSpec> formats() const;
  // "align, fiducials or shape": the kinds whose results offer what `wanted` picks, for messages.
  [[nodiscard]] std::string namesOffering(bool StepOffers::*wanted) const;

 private:
  std::vector<std::unique_ptr<StepKind>> kinds_;
};

}  // namespace facet::config
