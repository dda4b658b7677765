#include "config/training_record.hpp"

#include <fstream>
#include <sstream>
#include <stdexcept>

#include <nlohmann/json.hpp>

#include "config/content_hash.hpp"

namespace facet::config {
namespace {

// Non-throwing file checks: a name too long for the file system, a loop of links or a folder
// we may not read mean "not there", reported as such, never an exception out of the loader.
bool isFile(const std::filesystem::path& p) {
  std::error_code ec;
  return std::filesystem::is_regular_file(p, ec);
}

}  // namespace

std::filesystem::path trainingRecordPath(const std::filesystem::path& model) {
  return model.string() + ".train.json";
}

ModelStatus modelStatus(const std::filesystem::path& model, const std::filesystem::path& source,
                        const std::string& parameters) {
  if (!isFile(model)) return {ModelState::Missing, "does not exist"};
  std::ifstream in(trainingRecordPath(model));
  nlohmann::json record;
  try {
    in >> record;
  } catch (const nlohmann::json::exception&) {
    return {ModelState::Untracked,
            "has no readable training record " + trainingRecordPath(model).filename().string()};
  }
  const auto sourceHash = fileHash(source);
  const auto modelHash = fileHash(model);
  if (record.value("source_hash", "") != sourceHash.value_or("?"))
    return {ModelState::Stale, "was trained from a different " + source.filename().string()};
  if (record.value("parameters", "") != parameters)
    return {ModelState::Stale, "was trained with other parameters (" +
                                   record.value("parameters", "") + ", now " + parameters + ")"};
  if (record.value("model_hash", "") != modelHash.value_or("?"))
    return {ModelState::Stale, "changed after training"};
  return {ModelState::Fresh, {}};
}

void writeTrainingRecord(const std::filesystem::path& model, const std::filesystem::path& source,
                         const std::string& parameters) {
  const auto sourceHash = fileHash(source);
  const auto modelHash = fileHash(model);
  if (!sourceHash) throw std::runtime_error(source.string() + ": cannot read");
  if (!modelHash) throw std::runtime_error(model.string() + ": cannot read");
  const nlohmann::json record{{"source", source.filename().string()},
                              {"source_hash", *sourceHash},
                              {"parameters", parameters},
                              {"model_hash", *modelHash}};
  std::ofstream out(trainingRecordPath(model));
  out << record.dump(2) << "\n";
  if (!out) throw std::runtime_error(trainingRecordPath(model).string() + ": cannot write");
}

}  // namespace facet::config
