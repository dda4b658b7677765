#include "config/confined_path.hpp"

#include <iterator>
#include <optional>
#include <system_error>

namespace facet::config {
namespace {

// Whether normalised absolute `path` is `root` or below it.
bool isInside(const std::filesystem::path& path, const std::filesystem::path& root) {
  auto p = path.begin();
  for (auto r = root.begin(); r != root.end(); ++r, ++p) {
    if (r->empty()) continue;  // trailing separator of root
    if (p == path.end() || *p != *r) return false;
  }
  return true;
}

std::filesystem::path normalisedRoot(const std::filesystem::path& root) {
  std::error_code ec;
  auto r = std::filesystem::weakly_canonical(std::filesystem::absolute(root), ec);
  if (ec) r = std::filesystem::absolute(root).lexically_normal();
  // "a/b/" normalises with an empty last element; drop it so that component-wise compares work.
  return r.has_filename() ? r : r.parent_path();
}

// The first place `path` reaches outside `root` through a symbolic link below `root`, whether or
// not the link's target exists: weakly_canonical() stops at a dangling link, yet writing a model
// file through one would create the file wherever it points. Links are followed by hand, the
// target taking the link's place in the path, at most kMaxLinks times (a loop counts as outside).
std::optional<std::filesystem::path> linkEscape(const std::filesystem::path& path,
                                                const std::filesystem::path& root) {
  constexpr int kMaxLinks = 40;
  std::filesystem::path current = path;
  for (int followed = 0; followed <= kMaxLinks; ++followed) {
    std::filesystem::path prefix;
    bool relinked = false;
    for (auto part = current.begin(); part != current.end() && !relinked; ++part) {
      prefix /= *part;
      std::error_code ec;
      if (!isInside(prefix, root) || !std::filesystem::is_symlink(prefix, ec)) continue;
      const std::filesystem::path target = std::filesystem::read_symlink(prefix, ec);
      if (ec) return prefix;
      std::filesystem::path next = prefix.parent_path() / target;  // absolute targets replace
      for (auto rest = std::next(part); rest != current.end(); ++rest) next /= *rest;
      next = next.lexically_normal();
      if (!isInside(next, root)) return next;
      current = next;
      relinked = true;
    }
    if (!relinked) return std::nullopt;
  }
  return current;
}

}  // namespace

std::variant<std::filesystem::path, std::string> confinedPath(const std::string& written,
                                                              const std::filesystem::path& base,
                                                              const std::filesystem::path& root) {
  const std::filesystem::path p(written);
  if (p.is_absolute() || p.has_root_name() || p.has_root_directory())
    return std::string("is absolute; write it relative to the recipe");
  const std::filesystem::path rootPath = normalisedRoot(root);
  const std::filesystem::path basePath = normalisedRoot(base);
  const std::filesystem::path lexical = (basePath / p).lexically_normal();
  if (!isInside(lexical, rootPath)) return "leaves the recipes folder " + rootPath.string();
  // Symbolic links: the real location of whatever exists of the path must stay inside too.
  std::error_code ec;
  const std::filesystem::path real = std::filesystem::weakly_canonical(lexical, ec);
  if (!ec && !isInside(real, rootPath))
    return "leaves the recipes folder " + rootPath.string() + " through a symbolic link (to " +
           real.string() + ")";
  if (const auto escape = linkEscape(lexical, rootPath))
    return "leaves the recipes folder " + rootPath.string() + " through a symbolic link (to " +
           escape->string() + ")";
  return lexical;
}

}  // namespace facet::config
