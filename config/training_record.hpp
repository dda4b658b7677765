#pragma once
// What a trained file (a shape model) was made from, kept beside it as `<model>.train.json`:
// the hash of the source image, the training parameters and the hash of the model itself. When
// the image or the parameters in the recipe change after training, the model is stale and the
// recipe is refused until `facet recipe train` runs again; a model replaced by hand is noticed
// the same way.

#include <filesystem>
#include <string>

namespace facet::config {

enum class ModelState {
  Missing,    // no model file
  Untracked,  // a model file without a readable training record
  Stale,      // the source, the parameters or the model changed since training
  Fresh,
};

struct ModelStatus {
  ModelState state = ModelState::Missing;
  std::string detail;  // why it is not Fresh, for messages
};

std::filesystem::path trainingRecordPath(const std::filesystem::path& model);

// `parameters`: the training parameters as canonical text (what changes the model when changed).
ModelStatus modelStatus(const std::filesystem::path& model, const std::filesystem::path& source,
                        const std::string& parameters);

// Records that `model` was just trained from `source` with `parameters`. Throws
// std::runtime_error when a file cannot be read or written.
void writeTrainingRecord(const std::filesystem::path& model, const std::filesystem::path& source,
                         const std::string& parameters);

}  // namespace facet::config
