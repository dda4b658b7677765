#include "camera/sidecar_metadata.hpp"

#include <fstream>
#include <sstream>

#include <spdlog/spdlog.h>
#include <nlohmann/json.hpp>

#include "camera/camera.hpp"

namespace facet {
namespace {

// Parses a JSON object file; throws CameraError with the file name and the parser's position.
nlohmann::json readJsonObject(const std::filesystem::path& file) {
  std::ifstream in(file, std::ios::binary);
  if (!in) throw CameraError(file.string() + ": cannot open");
  nlohmann::json j;
  try {
    j = nlohmann::json::parse(in);
  } catch (const nlohmann::json::parse_error& e) {
    throw CameraError(file.string() + ": invalid JSON at byte " + std::to_string(e.byte) + ": " +
                      e.what());
  }
  if (!j.is_object()) throw CameraError(file.string() + ": expected a JSON object");
  return j;
}

void mergeInto(SidecarMetadata::Entries& entries, const nlohmann::json& object) {
  // The scene generator (tests/support/scene) writes serial, expected_verdict, pose, ... under
  // "annotations": those become entries too, top-level keys of the same name winning.
  if (auto it = object.find("annotations"); it != object.end() && it->is_object())
    for (const auto& [key, value] : it->items())
      if (!object.contains(key))
        entries[key] = value.is_string() ? value.get<std::string>() : value.dump();
  for (const auto& [key, value] : object.items())
    entries[key] = value.is_string() ? value.get<std::string>() : value.dump();
}

}  // namespace

SidecarMetadata SidecarMetadata::loadFolder(const std::filesystem::path& folder) {
  SidecarMetadata sidecar;
  const auto file = folder / "sidecar.json";
  std::error_code ec;
  if (!std::filesystem::exists(file, ec)) return sidecar;
  const nlohmann::json j = readJsonObject(file);
  if (auto it = j.find("defaults"); it != j.end()) {
    if (!it->is_object()) throw CameraError(file.string() + ": \"defaults\" must be an object");
    mergeInto(sidecar.defaults_, *it);
  }
  if (auto it = j.find("images"); it != j.end()) {
    if (!it->is_object()) throw CameraError(file.string() + ": \"images\" must be an object");
    for (const auto& [name, entry] : it->items()) {
      if (!entry.is_object())
        throw CameraError(file.string() + ": \"images\".\"" + name + "\" must be an object");
      mergeInto(sidecar.images_[name], entry);
    }
  }
  return sidecar;
}

SidecarMetadata::Entries SidecarMetadata::forImage(const std::filesystem::path& image,
                                                   std::string* error) const {
  Entries entries = defaults_;
  const std::string name = image.filename().string();
  if (auto it = images_.find(name); it != images_.end())
    for (const auto& [key, value] : it->second) entries[key] = value;

  auto own = image;
  own += ".json";
  std::error_code ec;
  if (std::filesystem::exists(own, ec)) {
    try {
      mergeInto(entries, readJsonObject(own));
    } catch (const CameraError& e) {
      spdlog::error("replay: ignoring sidecar {}", e.what());
      if (error) *error = e.what();
    }
  }
  return entries;
}

}  // namespace facet
