#pragma once
// Metadata recorded beside replayed images (part serial, expected verdict, ...), so a replayed
// folder doubles as a regression test.
//
// Two sources, later ones overriding earlier ones key by key:
//   1. <folder>/sidecar.json  {"defaults": {...}, "images": {"<file name>": {...}}}
//   2. <image file name>.json {...}   (e.g. part_0001.png.json)
// Top-level keys become metadata entries: strings as they are, other JSON values as JSON text;
// so do the keys of an "annotations" object (the scene generator's sidecars), unless a
// top-level key has the same name.

#include <filesystem>
#include <map>
#include <string>

#include <nlohmann/json_fwd.hpp>

namespace facet {

class SidecarMetadata {
 public:
  using Entries = std::map<std::string, std::string>;

  // Reads <folder>/sidecar.json if present. Throws CameraError naming the file (and the byte
  // offset of a syntax error) when it is present but malformed.
  static SidecarMetadata loadFolder(const std::filesystem::path& folder);

  // The merged metadata of one image. A malformed per-image sidecar is logged (naming the
  // file), reported through `error`, and ignored; the folder entries still apply.
  Entries forImage(const std::filesystem::path& image, std::string* error = nullptr) const;

 private:
  Entries defaults_;
  std::map<std::string, Entries> images_;
};

}  // namespace facet
