// `facet replay --shard`, `facet results merge` and `facet validate` through the real binary.
#include <gtest/gtest.h>
#include <sqlite3.h>

#include <fstream>

#include <nlohmann/json.hpp>

#include "tests/daemon/child_process.hpp"
#include "tests/support/cli/facet_cli.hpp"

namespace facet::test {
namespace {

using namespace std::chrono_literals;

const std::string kRecipe = "recipes/bracket_registration.recipe.yaml";
const std::string kImages = "recipes/demo/bracket_registration";
const std::string kStation = "recipes/station.yaml";

// Every row of both tables, without what differs between two runs of the same inspection (the
// wall-clock time and the step timings).
std::vector<std::string> rows(const std::string& file) {
  sqlite3* db = nullptr;
  sqlite3_open_v2(file.c_str(), &db, SQLITE_OPEN_READONLY, nullptr);
  std::vector<std::string> out;
  for (const char* sql :
       {"SELECT part_id, recipe_id, recipe_name, recipe_version, frame_id, source, serial, "
        "expected, verdict, failed_checks, error FROM parts ORDER BY part_id",
        "SELECT * FROM measurements ORDER BY part_id, name"}) {
    sqlite3_stmt* s = nullptr;
    sqlite3_prepare_v2(db, sql, -1, &s, nullptr);
    while (sqlite3_step(s) == SQLITE_ROW) {
      std::string row;
      for (int c = 0; c < sqlite3_column_count(s); ++c) {
        const auto* text = sqlite3_column_text(s, c);
        row += std::string(text ? reinterpret_cast<const char*>(text) : "NULL") + "|";
      }
      out.push_back(row);
    }
    sqlite3_finalize(s);
  }
  sqlite3_close(db);
  return out;
}

std::vector<std::string> replayArgs(const std::string& results) {
  return {FACET_CLI,   "replay", "--recipe",  kRecipe, "--images", kImages,
          "--station", kStation, "--results", results, "--json"};
}

TEST(ReplayShards, ThreeShardsAsProcessesGiveExactlyTheRowsOfOneRun) {
  daemon_test::TempDir dir;
  const auto whole =
      runFacet("replay --recipe " + kRecipe + " --images " + kImages + " --station " + kStation +
               " --results " + (dir / "whole.db") + " --json");
  ASSERT_EQ(whole.exitCode, 0) << whole.err;
  const auto summary = nlohmann::json::parse(whole.out);
  EXPECT_EQ(summary["shard"], "0/1");
  const auto expected = rows(dir / "whole.db");
  ASSERT_GT(summary["images"].get<int>(), 3);

  // Three shards at once, as separate processes; the third takes its index from the
  // environment as a pod of an Indexed Job does.
  std::vector<std::unique_ptr<daemon_test::ChildProcess>> shards;
  for (int i = 0; i < 2; ++i) {
    auto args = replayArgs(dir / ("shard" + std::to_string(i) + ".db"));
    args.insert(args.end(), {"--shard", std::to_string(i) + "/3"});
    shards.push_back(std::make_unique<daemon_test::ChildProcess>(args));
  }
  shards.push_back(std::make_unique<daemon_test::ChildProcess>(
      replayArgs(dir / "shard2.db"),
      std::map<std::string, std::string>{{"JOB_COMPLETION_INDEX", "2"}, {"JOB_COMPLETIONS", "3"}}));
  int taken = 0;
  std::size_t largest = 0;  // a shard's share follows its names' hashes: one may be empty
  std::vector<int> shareOf;
  for (auto& s : shards) {
    ASSERT_EQ(s->wait(300s), 0) << s->outputTail();
    const auto lines = s->lines();
    ASSERT_FALSE(lines.empty());
    shareOf.push_back(nlohmann::json::parse(lines.back())["images"].get<int>());
    taken += shareOf.back();
    if (shareOf.back() > shareOf[largest]) largest = shareOf.size() - 1;
  }
  EXPECT_EQ(taken, summary["images"].get<int>());
  const auto merge = runFacet("results merge " + (dir / "shard0.db") + " " + (dir / "shard1.db") +
                              " " + (dir / "shard2.db") + " --out " + (dir / "all.db"));
  ASSERT_EQ(merge.exitCode, 0) << merge.err;
  EXPECT_EQ(rows(dir / "all.db"), expected);

  // Merging a shard twice is refused, naming the repeated part.
  const std::string again = dir / ("shard" + std::to_string(largest) + ".db");
  ASSERT_GT(shareOf[largest], 0);
  const auto twice =
      runFacet("results merge " + again + " " + again + " --out " + (dir / "twice.db"));
  EXPECT_EQ(twice.exitCode, 1);
  EXPECT_NE(twice.err.find("is in an earlier input"), std::string::npos) << twice.err;
}

TEST(ReplayShards, BadShardIsAClearError) {
  daemon_test::TempDir dir;
  const auto r = runFacet("replay --recipe " + kRecipe + " --images " + kImages + " --station " +
                          kStation + " --results " + (dir / "x.db") + " --shard 3/3");
  EXPECT_EQ(r.exitCode, 1);
  EXPECT_NE(r.err.find("must be below 3"), std::string::npos) << r.err;
}

TEST(Validate, RecordedFolderPassesAndAChangedExpectationFailsWithATable) {
  daemon_test::TempDir dir;
  const auto ok =
      runFacet("validate --recipe " + kRecipe + " --golden " + kImages + " --station " + kStation);
  ASSERT_EQ(ok.exitCode, 0) << ok.out << ok.err;
  EXPECT_NE(ok.out.find(" 0 not"), std::string::npos) << ok.out;

  // A copy of the golden set in which one part is recorded with the other verdict, and one
  // with an expected value the recipe cannot meet.
  const std::filesystem::path golden = dir / "golden";
  std::filesystem::copy(kImages, golden);
  auto edit = [&](const std::string& sidecar, const std::function<void(nlohmann::json&)>& change) {
    nlohmann::json j = nlohmann::json::parse(std::ifstream(golden / sidecar));
    change(j);
    std::ofstream(golden / sidecar) << j.dump(2);
  };
  std::string flipped;
  edit("part_000.png.json", [&](nlohmann::json& j) {
    auto& v = j.contains("annotations") ? j["annotations"] : j;
    flipped = v["expected_verdict"] == "pass" ? "fail" : "pass";
    v["expected_verdict"] = flipped;
  });
  edit("part_001.png.json", [](nlohmann::json& j) {
    j["expected_values"] = {{"no_such_step.value", {{"value", 1.0}, {"tolerance", 0.1}}}};
  });
  const auto bad = runFacet("validate --recipe " + kRecipe + " --golden " + golden.string() +
                            " --station " + kStation);
  EXPECT_EQ(bad.exitCode, 3) << bad.out << bad.err;
  EXPECT_NE(bad.out.find("file"), std::string::npos) << bad.out;
  EXPECT_NE(bad.out.find("part_000.png"), std::string::npos) << bad.out;
  EXPECT_NE(bad.out.find("part_001.png"), std::string::npos) << bad.out;
  EXPECT_NE(bad.out.find("no_such_step.value"), std::string::npos) << bad.out;
  EXPECT_NE(bad.out.find(" 2 not"), std::string::npos) << bad.out;
  const auto json = runFacet("validate --json --recipe " + kRecipe + " --golden " +
                             golden.string() + " --station " + kStation);
  EXPECT_EQ(json.exitCode, 3);
  const auto j = nlohmann::json::parse(json.out);
  ASSERT_EQ(j["mismatches"].size(), 2u);
  EXPECT_EQ(j["mismatches"][0]["check"], "verdict");
  EXPECT_EQ(j["mismatches"][0]["expected"], flipped);
}

}  // namespace
}  // namespace facet::test
