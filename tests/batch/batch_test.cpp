// Shards, results merge and the golden-set comparison, without the command line.
#include <gtest/gtest.h>
#include <sqlite3.h>

#include <cstdlib>
#include <set>

#include "service/batch/golden_set.hpp"
#include "service/batch/results_merge.hpp"
#include "service/batch/shard.hpp"
#include "service/daemon/results_store.hpp"
#include "tests/daemon/child_process.hpp"
#include "tests/sinks/sample_part.hpp"

namespace facet::service {
namespace {

TEST(Shard, HashIsFnv1a64) {
  // The published FNV-1a test vectors: a shard must never move when the compiler changes.
  EXPECT_EQ(stableNameHash(""), 0xcbf29ce484222325ULL);
  EXPECT_EQ(stableNameHash("a"), 0xaf63dc4c8601ec8cULL);
  EXPECT_EQ(stableNameHash("foobar"), 0x85944171f73967e8ULL);
}

TEST(Shard, EveryFileIsInExactlyOneShardWhateverItsFolder) {
  constexpr int kCount = 7;
  std::vector<int> perShard(kCount, 0);
  for (int i = 0; i < 7000; ++i) {
    const std::string name = "part_" + std::to_string(i) + ".png";
    int owners = 0;
    for (int s = 0; s < kCount; ++s) {
      const Shard shard{s, kCount};
      const bool here = shard.takes("/archive/line3/" + name);
      EXPECT_EQ(here, shard.takes("/mnt/other/" + name)) << "the folder must not matter";
      owners += here ? 1 : 0;
      perShard[s] += here ? 1 : 0;
    }
    ASSERT_EQ(owners, 1) << name;
  }
  // Even enough that no pod idles: within 10% of 1000 each.
  for (int n : perShard) EXPECT_NEAR(n, 1000, 100);
}

TEST(Shard, ParsesIOverNAndRefusesNonsense) {
  EXPECT_EQ(parseShard("2/5").index, 2);
  EXPECT_EQ(parseShard("2/5").count, 5);
  EXPECT_THROW(parseShard("5/5"), std::invalid_argument);
  EXPECT_THROW(parseShard("1/0"), std::invalid_argument);
  EXPECT_THROW(parseShard("-1/4"), std::invalid_argument);
  EXPECT_THROW(parseShard("1"), std::invalid_argument);
  EXPECT_THROW(parseShard("a/b"), std::invalid_argument);
}

TEST(Shard, ComesFromAnIndexedJobsEnvironment) {
  ::unsetenv("JOB_COMPLETION_INDEX");
  ::unsetenv("JOB_COMPLETIONS");
  EXPECT_FALSE(shardFromEnvironment());
  ::setenv("JOB_COMPLETION_INDEX", "3", 1);
  EXPECT_THROW(shardFromEnvironment(), std::invalid_argument);  // count missing
  ::setenv("JOB_COMPLETIONS", "8", 1);
  const auto shard = shardFromEnvironment();
  ASSERT_TRUE(shard);
  EXPECT_EQ(shard->text(), "3/8");
  ::setenv("JOB_COMPLETIONS", "3", 1);
  EXPECT_THROW(shardFromEnvironment(), std::invalid_argument);
  ::unsetenv("JOB_COMPLETION_INDEX");
  ::unsetenv("JOB_COMPLETIONS");
}

TEST(ResultsMerge, JoinsStoresRowForRowAndRefusesOverlaps) {
  daemon_test::TempDir dir;
  {
    ResultsStore a(dir / "a.db"), b(dir / "b.db");
    for (std::uint64_t i = 1; i <= 9; ++i) (i % 2 ? a : b).store(sinks_test::samplePart(i));
  }
  const auto merged = mergeResults({dir / "a.db", dir / "b.db"}, dir / "all.db");
  ASSERT_EQ(merged.size(), 2u);
  EXPECT_EQ(merged[0].parts, 5);
  EXPECT_EQ(merged[1].parts, 4);
  EXPECT_EQ(merged[1].measurements, 8);
  const ResultsStore all(dir / "all.db");
  const auto parts = all.query({});
  ASSERT_EQ(parts.size(), 9u);
  for (std::size_t i = 0; i < parts.size(); ++i) {
    const auto want = sinks_test::samplePart(i + 1);
    EXPECT_EQ(parts[i].partId, want.partId);
    EXPECT_EQ(parts[i].serial, want.serial);
    EXPECT_EQ(parts[i].verdict, want.verdict);
    ASSERT_EQ(parts[i].measurements.size(), 2u);
    EXPECT_EQ(parts[i].measurements[0].value, want.measurements[0].value);
  }
  try {
    mergeResults({dir / "a.db", dir / "a.db"}, dir / "twice.db");
    FAIL() << "the same file twice must be refused";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("part 1 is in an earlier input"), std::string::npos)
        << e.what();
  }
  EXPECT_FALSE(std::filesystem::exists(dir / "twice.db"));
  EXPECT_THROW(mergeResults({dir / "a.db"}, dir / "all.db"), std::runtime_error);  // exists
  EXPECT_THROW(mergeResults({dir / "missing.db"}, dir / "x.db"), std::runtime_error);
}

// Recorded defects travel with the rows; a shard from a store without the column merges with
// them empty.
TEST(ResultsMerge, CarriesRecordedDefectsAndTakesAShardWithoutTheColumn) {
  daemon_test::TempDir dir;
  {
    ResultsStore a(dir / "a.db"), b(dir / "b.db");
    auto bad = sinks_test::samplePart(1);
    bad.recordedDefect = "big hole";
    bad.notes = {"edge: measured inside only"};
    a.store(bad);
    b.store(sinks_test::samplePart(2));
  }
  sqlite3* db = nullptr;
  ASSERT_EQ(sqlite3_open((dir / "b.db").c_str(), &db), SQLITE_OK);
  for (const char* drop :
       {"ALTER TABLE parts DROP COLUMN defect", "ALTER TABLE parts DROP COLUMN notes"})
    ASSERT_EQ(sqlite3_exec(db, drop, nullptr, nullptr, nullptr), SQLITE_OK) << sqlite3_errmsg(db);
  sqlite3_close(db);
  mergeResults({dir / "a.db", dir / "b.db"}, dir / "all.db");
  const auto parts = ResultsStore(dir / "all.db").query({});
  ASSERT_EQ(parts.size(), 2u);
  EXPECT_EQ(parts[0].recordedDefect, "big hole");
  EXPECT_EQ(parts[1].recordedDefect, "");
  EXPECT_EQ(parts[0].notes, std::vector<std::string>{"edge: measured inside only"});
  EXPECT_TRUE(parts[1].notes.empty());
}

TEST(GoldenSet, ReportsVerdictAndValueMismatches) {
  auto part = sinks_test::samplePart(7);  // fail, bore.diameter = 12.07
  EXPECT_TRUE(compareWithGolden(part, {{"expected_verdict", "fail"}}).empty());
  const auto verdict = compareWithGolden(part, {{"expected_verdict", "pass"}});
  ASSERT_EQ(verdict.size(), 1u);
  EXPECT_EQ(verdict[0].check, "verdict");
  EXPECT_EQ(verdict[0].got, "fail (bore.diameter)");
  EXPECT_EQ(verdict[0].file, "part-7.png");
  EXPECT_EQ(compareWithGolden(part, {}).size(), 1u);  // no expectation is a mismatch too
  const SidecarMetadata::Entries values{
      {"expected_verdict", "fail"},
      {"expected_values",
       R"({"bore.diameter": {"value": 12.06, "tolerance": 0.02}, "missing.value": {"value": 1}})"}};
  const auto found = compareWithGolden(part, values);
  ASSERT_EQ(found.size(), 1u);
  EXPECT_EQ(found[0].check, "missing.value");
  EXPECT_EQ(found[0].got, "not measured");
  const auto off = compareWithGolden(
      part, {{"expected_verdict", "fail"},
             {"expected_values", R"({"bore.diameter": {"value": 12.0, "tolerance": 0.05}})"}});
  ASSERT_EQ(off.size(), 1u);
  EXPECT_EQ(off[0].got, "12.0700 (+0.0700)");
}

}  // namespace
}  // namespace facet::service
