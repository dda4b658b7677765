#include "config/recipe_library.hpp"

#include <sys/stat.h>

#include <algorithm>
#include <set>

namespace facet::config {

RecipeLibrary::RecipeLibrary(const StepKindRegistry& kinds, RecipeLoadOptions options)
    : kinds_(kinds), options_(std::move(options)) {
  root_ = std::filesystem::absolute(options_.root.value_or(".")).lexically_normal();
  options_.root = root_;
}

RecipeLibrary::FileStamp RecipeLibrary::stamp(const std::filesystem::path& file) {
  FileStamp s;
  struct stat st {};
  if (::stat(file.c_str(), &st) != 0 || !S_ISREG(st.st_mode)) return s;
  auto ns = [](const timespec& t) { return std::int64_t{t.tv_sec} * 1'000'000'000 + t.tv_nsec; };
  s.exists = true;
  s.device = st.st_dev;
  s.inode = st.st_ino;
  s.size = static_cast<std::uint64_t>(st.st_size);
  s.modifiedNs = ns(st.st_mtim);
  s.changedNs = ns(st.st_ctim);
  return s;
}

std::vector<std::filesystem::path> RecipeLibrary::recipeFiles() const {
  std::vector<std::filesystem::path> files;
  std::error_code ec;
  for (auto it = std::filesystem::recursive_directory_iterator(
           root_, std::filesystem::directory_options::skip_permission_denied, ec);
       !ec && it != std::filesystem::recursive_directory_iterator(); it.increment(ec)) {
    const std::string name = it->path().filename().string();
    if (name.size() > kRecipeFileSuffix.size() && name.ends_with(kRecipeFileSuffix) &&
        it->is_regular_file())
      files.push_back(it->path().lexically_normal());
  }
  std::sort(files.begin(), files.end());
  return files;
}

ReloadReport RecipeLibrary::reload() {
  std::lock_guard reloading(reloadMutex_);
  std::map<std::filesystem::path, Entry> entries;
  {
    std::lock_guard lock(mutex_);
    entries = entries_;
  }
  ReloadReport report;
  const auto files = recipeFiles();

  // Read what changed; remember which files produced a new valid version.
  std::vector<std::filesystem::path> candidates;
  std::map<std::filesystem::path, std::shared_ptr<const Recipe>> fresh;
  for (const auto& file : files) {
    auto it = entries.find(file);
    if (it != entries.end()) {
      const Stamps& old = it->second.stamps;
      const bool same = std::all_of(old.begin(), old.end(),
                                    [](const auto& kv) { return stamp(kv.first) == kv.second; });
      // A file that lost an id to another one is read again: the other one may be gone.
      if (same && !it->second.lostIdClaim) continue;
    }
    RecipeLoadResult result = loadRecipe(file, kinds_, options_);
    Entry& entry = entries[file];
    entry.stamps.clear();
    for (const auto& f : result.files) entry.stamps[f] = stamp(f);
    entry.problems = result.diagnostics;
    entry.lostIdClaim = false;
    report.diagnostics.append(result.diagnostics);
    if (result.recipe) {
      fresh[file] = std::make_shared<const Recipe>(std::move(*result.recipe));
    } else {
      report.rejected.push_back(file);
    }
  }

  // Files that are gone take their recipes with them.
  const std::set<std::filesystem::path> present(files.begin(), files.end());
  for (auto it = entries.begin(); it != entries.end();) {
    if (present.contains(it->first)) {
      ++it;
      continue;
    }
    if (it->second.good) report.removed.push_back(it->second.good->id);
    it = entries.erase(it);
  }

  // Recipe ids are unique in the folder: recipes in use keep theirs; a new or changed file that
  // claims an id in use is rejected.
  std::map<int, std::filesystem::path> claims;
  for (const auto& [file, entry] : entries)
    if (entry.good && !fresh.contains(file)) claims.emplace(entry.good->id, file);
  for (auto& [file, recipe] : fresh) {
    const auto claim = claims.find(recipe->id);
    Entry& entry = entries[file];
    if (claim != claims.end() && claim->second != file) {
      Diagnostics duplicate;
      duplicate.error(recipe->idWhere, "recipe id " + std::to_string(recipe->id) +
                                           " is already used by " + claim->second.string());
      entry.problems.append(duplicate);
      entry.lostIdClaim = true;
      report.diagnostics.append(duplicate);
      report.rejected.push_back(file);
      continue;
    }
    if (entry.good && entry.good->id != recipe->id) claims.erase(entry.good->id);
    claims[recipe->id] = file;
    entry.good = recipe;
    entry.problems = {};  // warnings were reported with this reload
    report.loaded.push_back(recipe->id);
  }

  std::lock_guard lock(mutex_);
  entries_ = std::move(entries);
  return report;
}

bool RecipeLibrary::changedOnDisk() const {
  const auto files = recipeFiles();
  std::lock_guard lock(mutex_);
  if (files.size() != entries_.size()) return true;
  for (const auto& file : files) {
    const auto it = entries_.find(file);
    if (it == entries_.end()) return true;
    for (const auto& [f, s] : it->second.stamps)
      if (stamp(f) != s) return true;
  }
  return false;
}

std::shared_ptr<const Recipe> RecipeLibrary::find(int id) const {
  std::lock_guard lock(mutex_);
  for (const auto& [file, entry] : entries_)
    if (entry.good && entry.good->id == id) return entry.good;
  return nullptr;
}

std::vector<std::shared_ptr<const Recipe>> RecipeLibrary::recipes() const {
  std::vector<std::shared_ptr<const Recipe>> all;
  {
    std::lock_guard lock(mutex_);
    for (const auto& [file, entry] : entries_)
      if (entry.good) all.push_back(entry.good);
  }
  std::sort(all.begin(), all.end(), [](const auto& a, const auto& b) { return a->id < b->id; });
  return all;
}

Diagnostics RecipeLibrary::problems() const {
  Diagnostics all;
  std::lock_guard lock(mutex_);
  for (const auto& [file, entry] : entries_) all.append(entry.problems);
  return all;
}

}  // namespace facet::config
