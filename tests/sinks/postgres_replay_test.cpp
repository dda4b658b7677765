// `facet replay --postgres`: a batch re-inspection's shards, as separate processes, write to a
// throw-away PostgreSQL cluster exactly the parts of one unsharded run to SQLite; a shard started
// again resumes without writing a part twice; a server that is away is a clear error.
#include <gtest/gtest.h>

#include <cstdlib>

#include <nlohmann/json.hpp>

#include "tests/sinks/postgres_cluster.hpp"
#include "tests/support/cli/facet_cli.hpp"

namespace facet::sinks_test {
namespace {

using namespace std::chrono_literals;

const std::string kReplay =
    "replay --recipe recipes/bracket_registration.recipe.yaml --images "
    "recipes/demo/bracket_registration --station recipes/station.yaml --json ";

// Every part of a `facet results export --json`, by part id, without what differs between two
// runs of the same inspection (wall-clock time, durations) and the station.
std::map<std::uint64_t, nlohmann::json> comparable(const std::string& exportJson) {
  std::map<std::uint64_t, nlohmann::json> parts;
  const auto exported = nlohmann::json::parse(exportJson);  // outlives the loop over its parts
  for (auto part : exported.at("parts")) {
    for (const char* key : {"time", "inspection_ms", "timings_ms", "station"}) part.erase(key);
    const auto id = part.at("part_id").get<std::uint64_t>();
    parts[id] = part;
  }
  return parts;
}

TEST(ReplayToPostgres, ShardsAsProcessesWriteExactlyThePartsOfOneRunAndResumeWithoutRepeats) {
  daemon_test::TempDir dir;
  PostgresCluster db(dir.path());
  db.start();
  ::setenv("PGPASSWORD", PostgresCluster::kPassword, 1);  // as a Job's secret would set it
  const std::string central = " --postgres '" + db.connection() + "' --as-station recheck ";

  const auto whole = test::runFacet(kReplay + "--results " + (dir / "whole.db"));
  ASSERT_EQ(whole.exitCode, 0) << whole.err;
  const auto images = nlohmann::json::parse(whole.out)["images"].get<std::size_t>();
  const auto expected = test::runFacet("results export --json --db " + (dir / "whole.db"));
  ASSERT_EQ(expected.exitCode, 0) << expected.err;

  // Three shards at once; the third from the environment, as a pod of an Indexed Job.
  std::vector<std::unique_ptr<daemon_test::ChildProcess>> shards;
  for (int i = 0; i < 3; ++i) {
    std::vector<std::string> args{FACET_CLI,      "replay",
                                  "--recipe",     "recipes/bracket_registration.recipe.yaml",
                                  "--images",     "recipes/demo/bracket_registration",
                                  "--station",    "recipes/station.yaml",
                                  "--postgres",   db.connection(),
                                  "--as-station", "recheck",
                                  "--json"};
    std::map<std::string, std::string> env{{"PGPASSWORD", PostgresCluster::kPassword}};
    if (i < 2)
      args.insert(args.end(), {"--shard", std::to_string(i) + "/3"});
    else
      env.insert({{"JOB_COMPLETION_INDEX", "2"}, {"JOB_COMPLETIONS", "3"}});
    shards.push_back(std::make_unique<daemon_test::ChildProcess>(args, env));
  }
  std::size_t taken = 0;
  for (auto& s : shards) {
    ASSERT_EQ(s->wait(300s), 0) << s->outputTail();
    const auto summary = nlohmann::json::parse(s->lines().back());
    EXPECT_EQ(summary["skipped"], 0);
    EXPECT_NE(summary["results"].get<std::string>().find("station recheck"), std::string::npos);
    taken += summary["images"].get<std::size_t>();
  }
  EXPECT_EQ(taken, images);
  const auto written = test::runFacet("results export --json --postgres '" + db.connection() +
                                      "' --station recheck");
  ASSERT_EQ(written.exitCode, 0) << written.err;
  EXPECT_EQ(comparable(written.out), comparable(expected.out));

  // The whole folder again under the same name: every part is there already, nothing twice.
  const auto again = test::runFacet(kReplay + central);
  ASSERT_EQ(again.exitCode, 0) << again.err;
  EXPECT_EQ(nlohmann::json::parse(again.out)["skipped"], images) << again.out;
  EXPECT_EQ(db.query("SELECT count(*) FROM parts WHERE station = 'recheck'"),
            std::to_string(images));

  // Half-written (a pod that died): the rest is written, the first half not again.
  EXPECT_EQ(db.query("WITH gone AS (DELETE FROM parts WHERE station = 'recheck' AND part_id > " +
                     std::to_string(images / 2) + " RETURNING 1) SELECT count(*) FROM gone"),
            std::to_string(images - images / 2));
  const auto resumed = test::runFacet(kReplay + central);
  ASSERT_EQ(resumed.exitCode, 0) << resumed.err;
  EXPECT_EQ(nlohmann::json::parse(resumed.out)["skipped"], images / 2) << resumed.out;
  const auto afterResume = test::runFacet("results export --json --postgres '" + db.connection() +
                                          "' --station recheck");
  EXPECT_EQ(comparable(afterResume.out), comparable(expected.out));

  // The default station name says which recipe (and which version of it) made the parts.
  const auto named = test::runFacet(kReplay + " --postgres '" + db.connection() + "'");
  ASSERT_EQ(named.exitCode, 0) << named.err;
  EXPECT_NE(nlohmann::json::parse(named.out)["results"].get<std::string>().find(
                "station replay-Bracket B-100, bores-"),
            std::string::npos)
      << named.out;
  ::unsetenv("PGPASSWORD");
}

TEST(ReplayToPostgres, AServerThatIsAwayOrAWrongPasswordIsAClearErrorAndNothingIsInspected) {
  daemon_test::TempDir dir;
  PostgresCluster db(dir.path());
  db.start();
  ::setenv("PGPASSWORD", "wrong", 1);
  const auto refused = test::runFacet(kReplay + " --postgres '" + db.connection() + "'");
  EXPECT_EQ(refused.exitCode, 1) << refused.out;
  EXPECT_NE(refused.err.find("postgres 127.0.0.1:" + std::to_string(db.port()) +
                             "/facet: cannot connect"),
            std::string::npos)
      << refused.err;
  EXPECT_EQ(refused.err.find("wrong"), std::string::npos) << refused.err;
  ::unsetenv("PGPASSWORD");

  db.kill();
  const auto away = test::runFacet(kReplay + " --postgres '" + db.connection() + "'");
  EXPECT_EQ(away.exitCode, 1) << away.out;
  EXPECT_NE(away.err.find("cannot connect"), std::string::npos) << away.err;
  EXPECT_TRUE(away.out.empty()) << away.out;

  const auto both = test::runFacet(kReplay + " --postgres x --results " + (dir / "x.db"));
  EXPECT_EQ(both.exitCode, 1);
  EXPECT_NE(both.err.find("exclude each other"), std::string::npos) << both.err;
}

}  // namespace
}  // namespace facet::sinks_test
