#pragma once
// Paths written in recipes stay inside the recipes folder: a recipe that can name
// /etc/shadow or ../../secrets as its "reference image" could leak files through the dashboard
// and the archive, and would break when the folder is copied to another station.

#include <filesystem>
#include <string>
#include <variant>

namespace facet::config {

// Resolves `written` (a path as written in a file) against `base`, the folder of that file, and
// checks that it stays inside `root`. Refused: absolute paths, paths whose `..` leave `root`, and
// paths that reach outside `root` through a symbolic link. Returns the absolute, normalised path
// or the reason it was refused (a message fragment such as "is absolute").
std::variant<std::filesystem::path, std::string> confinedPath(const std::string& written,
                                                              const std::filesystem::path& base,
                                                              const std::filesystem::path& root);

}  // namespace facet::config
