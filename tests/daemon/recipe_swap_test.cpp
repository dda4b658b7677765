// A recipe replaced by a broken one while facetd inspects parts, through both ways facetd
// reloads: SIGHUP, and its poll of the recipe files (once a second). The broken version must be
// rejected with its file and line in the log and in /healthz, the old version must keep
// inspecting (same verdicts, same recipe hash in the store), and once the file is repaired the
// new version must be used from one part on, never mixed back with the old one.
#include <gtest/gtest.h>

#include <algorithm>
#include <csignal>
#include <filesystem>
#include <fstream>
#include <sstream>

#include "tests/daemon/child_process.hpp"
#include "tests/daemon/facetd_http.hpp"
#include "tests/daemon/line_run.hpp"

namespace facet::daemon_test {
namespace {

using namespace std::chrono_literals;
namespace fs = std::filesystem;
const std::string kDemo = std::string(FACET_SOURCE_DIR) + "/recipes/demo/bracket_shape";
const std::string kRecipeFile = "bracket_shape.recipe.yaml";  // recipe id 2

enum class ReloadBy { Sighup, FileChange };

std::string readFile(const std::string& file) {
  std::ostringstream s;
  s << std::ifstream(file).rdbuf();
  return s.str();
}

// Replaces the file the way an editor's safe save does (write aside, rename over), so that the
// daemon never reads a half-written file.
void replaceFile(const std::string& file, const std::string& text) {
  const std::string aside = file + ".new";
  std::ofstream(aside) << text;
  fs::rename(aside, file);
}

// `text` with the first `from` replaced by `to`; and the 1-based line where that happened.
std::pair<std::string, int> edit(std::string text, const std::string& from, const std::string& to) {
  const auto at = text.find(from);
  if (at == std::string::npos) throw std::runtime_error("recipe lacks '" + from + "'");
  const int line = 1 + static_cast<int>(std::count(text.begin(), text.begin() + at, '\n'));
  text.replace(at, from.size(), to);
  return {text, line};
}

bool contains(const std::string& line, const std::string& part) {
  return line.find(part) != std::string::npos;
}

class RecipeSwap {
 public:
  explicit RecipeSwap(ReloadBy how) : how_(how) {
    fs::copy(std::string(FACET_SOURCE_DIR) + "/recipes", dir_ / "recipes",
             fs::copy_options::recursive);
    recipeFile_ = dir_ / ("recipes/" + kRecipeFile);
    original_ = readFile(recipeFile_);
  }

  void run() {
    // Free run at 10 parts/s over the demo images; --block-when-behind: a slow machine delays
    // parts instead of dropping them, so every stored part must carry a real verdict.
    const auto station = writeStationFile(
        dir_.path(),
        "  backend: replay\n  replay:\n    folder: " + kDemo +
            "\n    glob: \"*.png\"\n    loop: true\n    fps: 10\n    trigger: free_run\n"
            "    colour: mono\n",
        0, {.recipes = dir_ / "recipes"});
    facetd_ = std::make_unique<ChildProcess>(
        std::vector<std::string>{FACETD_PATH, "--config", station, "--recipe", "2", "--no-plc",
                                 "--block-when-behind", "--http-port-file", dir_ / "http.port",
                                 "--log-level", "info"},
        std::map<std::string, std::string>{}, dir_ / "facetd.stderr");
    const auto port = waitForHttpPort(dir_ / "http.port", 30s);
    ASSERT_TRUE(port) << "facetd did not start; see " << dir_ / "facetd.stderr";
    port_ = *port;
    const std::string db = dir_ / "results.db";

    // 1. The original version inspects.
    auto parts = waitForStored(
        db, [](const auto& p) { return p.size() >= 5; }, 30s);
    ASSERT_TRUE(parts) << "fewer than 5 parts within 30 s";
    const std::string v1 = parts->front().recipeVersion;
    ASSERT_EQ(v1.size(), 16u) << "recipe_version is the file's FNV-1a hash";
    auto health = healthz(port_);
    ASSERT_TRUE(health.contains("recipe")) << health.dump();
    EXPECT_EQ(health["recipe"]["version"], v1);
    EXPECT_TRUE(health["recipe"]["problems"].empty()) << health.dump();
    EXPECT_EQ(health["status"], "ok") << health.dump();

    // 2. Broken: a value of the wrong type (SIGHUP) or an unknown step kind (file change).
    const auto [broken, brokenLine] = how_ == ReloadBy::Sighup
                                          ? edit(original_, "min_score: 0.7", "min_score: high")
                                          : edit(original_, "kind: circle", "kind: circel");
    const std::string where = recipeFile_ + ":" + std::to_string(brokenLine) + ":";
    replaceFile(recipeFile_, broken);
    if (how_ == ReloadBy::Sighup) facetd_->signal(SIGHUP);
    ASSERT_TRUE(facetd_->waitForLine(
        [&](const std::string& l) {
          return how_ == ReloadBy::Sighup
                     ? contains(l, "SIGHUP: recipes reloaded (0 changed, 1 rejected)")
                     : contains(l, "recipe files changed: 0 reloaded, 1 rejected");
        },
        10s))
        << "the broken recipe was not rejected by the "
        << (how_ == ReloadBy::Sighup ? "SIGHUP reload" : "file-change reload");
    const auto errorLine = facetd_->waitForLine(
        [&](const std::string& l) { return contains(l, "error") && contains(l, where); }, 1s);
    EXPECT_TRUE(errorLine) << "no error log line naming " << where;
    health = healthz(port_);
    EXPECT_EQ(health["status"], "degraded") << health.dump();
    EXPECT_EQ(health["recipe"]["version"], v1) << "the old version must stay in use";
    // The first problem is the edit; an unknown step kind also breaks the steps that use it.
    ASSERT_GE(health["recipe"]["problems"].size(), 1u) << health.dump();
    EXPECT_TRUE(contains(health["recipe"]["problems"][0].get<std::string>(), where))
        << health["recipe"]["problems"][0] << " should name " << where;

    // 3. The old version keeps inspecting.
    const std::int64_t atRejection = lastPartId(db);
    parts = waitForStored(
        db, [&](const auto& p) { return !p.empty() && p.back().partId >= atRejection + 8; }, 30s);
    ASSERT_TRUE(parts) << "parts stopped after the rejected reload";
    EXPECT_EQ(healthz(port_)["recipe"]["version"], v1);

    // 4. Repaired, as a new version (another name): picked up by the same way of reloading.
    const std::string fixed =
        edit(original_, "name: Bracket B-100, label", "name: Bracket B-100, label rev B").first;
    const std::int64_t beforeFix = lastPartId(db);
    replaceFile(recipeFile_, fixed);
    if (how_ == ReloadBy::Sighup) facetd_->signal(SIGHUP);
    ASSERT_TRUE(facetd_->waitForLine(
        [&](const std::string& l) {
          return how_ == ReloadBy::Sighup
                     ? contains(l, "SIGHUP: recipes reloaded (1 changed, 0 rejected)")
                     : contains(l, "recipe files changed: 1 reloaded, 0 rejected");
        },
        10s))
        << "the repaired recipe was not reloaded";
    parts = waitForStored(
        db,
        [&](const auto& p) {
          return std::count_if(p.begin(), p.end(),
                               [&](const StoredPart& s) { return s.recipeVersion != v1; }) >= 5;
        },
        30s);
    ASSERT_TRUE(parts) << "the repaired version inspected fewer than 5 parts within 30 s";
    health = healthz(port_);
    EXPECT_EQ(health["status"], "ok") << health.dump();
    EXPECT_TRUE(health["recipe"]["problems"].empty()) << health.dump();
    EXPECT_EQ(health["recipe"]["name"], "Bracket B-100, label rev B");
    const std::string v2 = health["recipe"]["version"];
    EXPECT_NE(v2, v1);

    facetd_->signal(SIGTERM);
    const auto code = facetd_->wait(20s);
    ASSERT_TRUE(code) << "facetd did not exit after SIGTERM";
    EXPECT_EQ(*code, 0);

    // 5. Every stored part: contiguous ids, the demo's verdict (none "error"), the old version
    // up to the repair and the new one from some part on, never back.
    const auto all = storedParts(db);
    EXPECT_EQ(integrityCheck(db), "ok");
    const auto expected = expectedParts(kDemo);
    std::int64_t firstNew = 0, oldAfterRejection = 0;
    for (std::size_t i = 0; i < all.size(); ++i) {
      const auto& p = all[i];
      const std::string part = "part " + std::to_string(p.partId);
      ASSERT_EQ(p.partId, static_cast<std::int64_t>(i) + 1) << "part ids have a hole";
      const std::string file = fs::path(p.source).filename().string();
      ASSERT_TRUE(expected.count(file)) << part << ": " << p.source;
      EXPECT_EQ(p.verdict, expected.at(file).verdict) << part << " (" << file << ") " << p.error;
      EXPECT_EQ(p.recipeId, 2) << part;
      if (p.recipeVersion == v1) {
        EXPECT_EQ(firstNew, 0) << part << " went back to the old version";
        EXPECT_EQ(p.recipeName, "Bracket B-100, label") << part;
        oldAfterRejection += p.partId > atRejection;
      } else {
        EXPECT_EQ(p.recipeVersion, v2) << part;
        EXPECT_EQ(p.recipeName, "Bracket B-100, label rev B") << part;
        EXPECT_GT(p.partId, beforeFix) << part << " used the repaired version before the repair";
        if (firstNew == 0) firstNew = p.partId;
      }
    }
    EXPECT_GE(oldAfterRejection, 8) << "the old version did not keep inspecting";
    EXPECT_GT(firstNew, 0);
    std::cout << "[ figures  ] " << all.size() << " parts; rejected at part " << atRejection << ", "
              << oldAfterRejection << " parts on the old version after the rejection, "
              << "new version from part " << firstNew << " (repair written after part " << beforeFix
              << ")\n";
  }

 private:
  std::int64_t lastPartId(const std::string& db) const {
    const auto parts = storedParts(db);
    return parts.empty() ? 0 : parts.back().partId;
  }

  ReloadBy how_;
  TempDir dir_;
  std::string recipeFile_, original_;
  std::unique_ptr<ChildProcess> facetd_;
  int port_ = 0;
};

TEST(RecipeSwap, BrokenRecipeRejectedOnSighupThenRepairedVersionUsed) {
  RecipeSwap(ReloadBy::Sighup).run();
}

TEST(RecipeSwap, BrokenRecipeRejectedOnFileChangeThenRepairedVersionUsed) {
  RecipeSwap(ReloadBy::FileChange).run();
}

}  // namespace
}  // namespace facet::daemon_test
