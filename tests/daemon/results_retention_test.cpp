// facetd applies the station file's results retention: a run with keep_parts starts by deleting
// the parts beyond the limit, keeps the newest, and numbers its own parts after the last stored
// one; a run without retention keeps everything.
#include <gtest/gtest.h>

#include "tests/daemon/child_process.hpp"
#include "tests/daemon/line_run.hpp"

namespace facet::daemon_test {
namespace {

using namespace std::chrono_literals;
const std::string kDemo = std::string(FACET_SOURCE_DIR) + "/recipes/demo/bracket_shape";

// facetd --replay over the demo folder once (12 parts); returns its exit code.
int replayOnce(const TempDir& dir, const std::string& station) {
  ChildProcess facetd({FACETD_PATH, "--config", station, "--recipe", "2", "--no-plc", "--replay",
                       kDemo, "--log-level", "info"},
                      {}, dir / "facetd.stderr");
  return facetd.wait(60s).value_or(-1);
}

std::vector<std::int64_t> partIds(const std::vector<StoredPart>& parts) {
  std::vector<std::int64_t> ids;
  for (const auto& p : parts) ids.push_back(p.partId);
  return ids;
}

TEST(ResultsRetention, KeepPartsTrimsTheStoreAtStartAndPartIdsContinue) {
  TempDir dir;
  const std::string camera = "  backend: replay\n  replay:\n    folder: " + kDemo + "\n";
  const std::string database = dir / "results.db";

  // Two runs without retention: 24 parts, ids 1..24.
  const auto keepAll = writeStationFile(dir.path(), camera, 0);
  ASSERT_EQ(replayOnce(dir, keepAll), 0);
  ASSERT_EQ(replayOnce(dir, keepAll), 0);
  ASSERT_EQ(storedParts(database).size(), 24u);

  // A third run with keep_parts: 5. At start the store keeps parts 20..24, then the run adds
  // 25..36 (the next clean-up is a minute away, longer than the run).
  const auto keepFive =
      writeStationFile(dir.path(), camera, 0, {.resultsExtra = "  keep_parts: 5\n"});
  ASSERT_EQ(replayOnce(dir, keepFive), 0);
  std::vector<std::int64_t> expected;
  for (std::int64_t id = 20; id <= 36; ++id) expected.push_back(id);
  EXPECT_EQ(partIds(storedParts(database)), expected);
  EXPECT_EQ(integrityCheck(database), "ok");
}

}  // namespace
}  // namespace facet::daemon_test
