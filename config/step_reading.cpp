#include "config/step_reading.hpp"

#include <algorithm>

#include "config/closest_name.hpp"
#include "config/confined_path.hpp"
#include "config/yaml_document.hpp"

namespace facet::config {
namespace {

std::string inQuotes(const std::string& s) {
  return "'" + s + "'";
}

// Non-throwing: a name too long for the file system, a loop of links or a folder we may not
// read mean "not there", reported as such, never an exception out of the loader.
bool isFile(const std::filesystem::path& p) {
  std::error_code ec;
  return std::filesystem::is_regular_file(p, ec);
}

std::string_view offerName(bool StepOffers::*wanted) {
  if (wanted == &StepOffers::pose) return "pose";
  if (wanted == &StepOffers::line) return "line";
  return "position";
}

}  // namespace

StepReading::StepReading(const YAML::Node& step, const std::filesystem::path& file,
                         const std::filesystem::path& baseFolder, const std::filesystem::path& root,
                         const RecipeLoadOptions& options, const StepKindRegistry& kinds,
                         const std::map<std::string, EarlierStep>& earlier,
                         const std::map<std::string, int>& allIds, Diagnostics& out)
    : step_(step),
      file_(file),
      baseFolder_(baseFolder),
      root_(root),
      options_(options),
      kinds_(kinds),
      earlier_(earlier),
      allIds_(allIds),
      out_(out) {}

SourceLocation StepReading::where(const YAML::Node& n) const {
  return locate(file_, n);
}

void StepReading::error(const YAML::Node& at, std::string message) {
  ++errors_;
  out_.error(where(at), std::move(message));
}

void StepReading::warning(const YAML::Node& at, std::string message) {
  out_.warning(where(at), std::move(message));
}

std::optional<std::string> StepReading::stepRef(const std::string& key, bool StepOffers::*wanted) {
  const YAML::Node n = step_[key];
  if (!n || !n.IsScalar()) return std::nullopt;
  const std::string id = n.Scalar();
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
  // A step whose own kind is unknown was reported where it stands; no second message here.
  if (it->second.kind != nullptr && !(it->second.kind->offers().*wanted)) {
    error(n, inQuotes(key) + " needs a step that gives a " + std::string(offerName(wanted)) + " (" +
                 kinds_.namesOffering(wanted) + "), but " + inQuotes(id) + " is a " +
                 std::string(it->second.kind->name()) + " step");
  }
  if (std::find(inputs_.begin(), inputs_.end(), id) == inputs_.end()) inputs_.push_back(id);
  return id;
}

std::optional<std::filesystem::path> StepReading::path(const std::string& key, bool mayBeMissing) {
  const YAML::Node n = step_[key];
  if (!n || !n.IsScalar() || n.Scalar().empty()) return std::nullopt;
  const auto resolved = confinedPath(n.Scalar(), baseFolder_, root_);
  if (const auto* problem = std::get_if<std::string>(&resolved)) {
    error(n, inQuotes(key) + " path " + inQuotes(n.Scalar()) + " " + *problem);
    return std::nullopt;
  }
  const auto& path = std::get<std::filesystem::path>(resolved);
  dependencies_.push_back(path);
  if (!mayBeMissing && !isFile(path)) {
    error(n, inQuotes(key) + " file " + inQuotes(n.Scalar()) + " does not exist (looked for " +
                 path.string() + ")");
    return std::nullopt;
  }
  return path;
}

}  // namespace facet::config
