#pragma once
// The recorded files of a replay folder, in the order an operator expects (img2 before img10).

#include <filesystem>
#include <string>
#include <string_view>
#include <vector>

namespace facet {

// "Natural" order: runs of digits compare by value (then by length, so "01" < "001" is stable),
// everything else byte by byte.
bool naturalLess(std::string_view a, std::string_view b);

// True when `name` matches `pattern` with '*' (any run) and '?' (one character).
bool globMatch(std::string_view pattern, std::string_view name);

// Regular files directly in `folder` whose name matches `glob` (or, with an empty glob, whose
// extension is in `default_extensions`, compared case-insensitively, e.g. {".png", ".tif"}),
// in natural order of their file names. Sidecar files (*.json) are never listed.
// Throws CameraError when the folder cannot be read.
std::vector<std::filesystem::path> listRecordedFiles(
    const std::filesystem::path& folder, const std::string& glob,
    const std::vector<std::string>& default_extensions);

}  // namespace facet
