#include "camera/image_file_list.hpp"

#include <algorithm>
#include <cctype>
#include <system_error>

#include "camera/camera.hpp"

namespace facet {
namespace {

bool isDigit(char c) {
  return c >= '0' && c <= '9';
}

std::string lowerCase(std::string s) {
  std::transform(s.begin(), s.end(), s.begin(),
                 [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  return s;
}

}  // namespace

bool naturalLess(std::string_view a, std::string_view b) {
  std::size_t i = 0;
  std::size_t j = 0;
  while (i < a.size() && j < b.size()) {
    if (isDigit(a[i]) && isDigit(b[j])) {
      // Compare digit runs by value without converting (runs may exceed 64 bits).
      std::size_t i0 = i;
      std::size_t j0 = j;
      while (i0 < a.size() && a[i0] == '0') ++i0;
      while (j0 < b.size() && b[j0] == '0') ++j0;
      std::size_t i1 = i0;
      std::size_t j1 = j0;
      while (i1 < a.size() && isDigit(a[i1])) ++i1;
      while (j1 < b.size() && isDigit(b[j1])) ++j1;
      if (i1 - i0 != j1 - j0) return i1 - i0 < j1 - j0;
      if (int c = a.substr(i0, i1 - i0).compare(b.substr(j0, j1 - j0)); c != 0) return c < 0;
      if (i1 - i != j1 - j) return i1 - i < j1 - j;  // fewer leading zeros first
      i = i1;
      j = j1;
      continue;
    }
    if (a[i] != b[j]) return static_cast<unsigned char>(a[i]) < static_cast<unsigned char>(b[j]);
    ++i;
    ++j;
  }
  return a.size() - i < b.size() - j;
}

bool globMatch(std::string_view pattern, std::string_view name) {
  // Iterative matcher with single-star backtracking: linear in practice, no recursion.
  std::size_t p = 0;
  std::size_t n = 0;
  std::size_t star = std::string_view::npos;
  std::size_t star_n = 0;
  while (n < name.size()) {
    if (p < pattern.size() && (pattern[p] == '?' || pattern[p] == name[n])) {
      ++p;
      ++n;
    } else if (p < pattern.size() && pattern[p] == '*') {
      star = p++;
      star_n = n;
    } else if (star != std::string_view::npos) {
      p = star + 1;
      n = ++star_n;
    } else {
      return false;
    }
  }
  while (p < pattern.size() && pattern[p] == '*') ++p;
  return p == pattern.size();
}

std::vector<std::filesystem::path> listRecordedFiles(
    const std::filesystem::path& folder, const std::string& glob,
    const std::vector<std::string>& default_extensions) {
  std::error_code ec;
  std::filesystem::directory_iterator it(folder, ec);
  if (ec) throw CameraError("cannot read folder " + folder.string() + ": " + ec.message());
  std::vector<std::filesystem::path> files;
  for (const auto& entry : it) {
    if (!entry.is_regular_file(ec)) continue;
    const std::string name = entry.path().filename().string();
    const std::string ext = lowerCase(entry.path().extension().string());
    if (ext == ".json") continue;
    const bool wanted = glob.empty()
                            ? std::find(default_extensions.begin(), default_extensions.end(),
                                        ext) != default_extensions.end()
                            : globMatch(glob, name);
    if (wanted) files.push_back(entry.path());
  }
  std::sort(files.begin(), files.end(), [](const auto& a, const auto& b) {
    return naturalLess(a.filename().string(), b.filename().string());
  });
  return files;
}

}  // namespace facet
