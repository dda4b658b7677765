#pragma once
// RecipeLibrary: the recipes of a station's folder, as the daemon uses them. reload() reads the
// folder again (the daemon calls it on SIGHUP and when changedOnDisk() says so); a recipe file
// that fails validation is rejected with its messages and the last good version of that recipe
// stays in use. Recipes are handed out as shared_ptr<const Recipe>, so an inspection that runs
// while a reload replaces its recipe keeps the version it started with: switching happens only
// between parts, when the daemon asks find() for the next one.
//
// Recipe files are the `*.recipe.yaml` files anywhere below the root. Thread-safe.

#include <cstdint>
#include <filesystem>
#include <map>
#include <memory>
#include <mutex>
#include <string>
#include <vector>

#include "config/diagnostic.hpp"
#include "config/recipe.hpp"
#include "config/recipe_loader.hpp"

namespace facet::config {

inline constexpr std::string_view kRecipeFileSuffix = ".recipe.yaml";

struct ReloadReport {
  std::vector<int> loaded;                      // ids of recipes that are new or changed, and valid
  std::vector<int> removed;                     // ids whose file is gone
  std::vector<std::filesystem::path> rejected;  // files with errors (an older version may stay)
  Diagnostics diagnostics;                      // every message of this reload

  [[nodiscard]] bool changed() const { return !loaded.empty() || !removed.empty(); }
};

class RecipeLibrary {
 public:
  // `options.root` is the recipes folder (required); recipes may use the step kinds of `kinds`,
  // which must outlive the library.
  RecipeLibrary(const StepKindRegistry& kinds, RecipeLoadOptions options);

  // Reads new and changed recipe files (and those whose images or models changed). Files that
  // did not change since the last reload are not read again.
  ReloadReport reload();

  // Whether a recipe file was added, removed or changed, or a file one names changed, since the
  // last reload(). Cheap: compares inodes, sizes and modification and status-change times.
  [[nodiscard]] bool changedOnDisk() const;

  [[nodiscard]] std::shared_ptr<const Recipe> find(int id) const;
  // Every usable recipe, by id.
  [[nodiscard]] std::vector<std::shared_ptr<const Recipe>> recipes() const;
  // The messages of the last reload() for files still rejected.
  [[nodiscard]] Diagnostics problems() const;
  [[nodiscard]] const std::filesystem::path& root() const { return root_; }

 private:
  // What tells a changed file from the one read: the modification time alone misses a file
  // replaced by one of the same size and time (cp -p, rsync -t, an editor keeping the time);
  // the status-change time cannot be set back and moves with every write, and a file renamed
  // into place has another inode.
  struct FileStamp {
    bool exists = false;
    std::uint64_t device = 0, inode = 0, size = 0;
    std::int64_t modifiedNs = 0, changedNs = 0;
    bool operator==(const FileStamp&) const = default;
  };
  using Stamps = std::map<std::filesystem::path, FileStamp>;
  struct Entry {
    std::shared_ptr<const Recipe> good;  // last valid version, may be null
    Stamps stamps;                       // of the files read at the last attempt
    Diagnostics problems;                // of the last attempt when it failed
    bool lostIdClaim = false;            // rejected only because another file has its id
  };

  static FileStamp stamp(const std::filesystem::path& file);
  std::vector<std::filesystem::path> recipeFiles() const;

  const StepKindRegistry& kinds_;
  RecipeLoadOptions options_;
  std::filesystem::path root_;
  std::mutex reloadMutex_;                          // one reload at a time
  mutable std::mutex mutex_;                        // guards entries_
  std::map<std::filesystem::path, Entry> entries_;  // by recipe file
};

}  // namespace facet::config
