// Reading the central PostgreSQL database back: readPostgresResults and `facet results export
// --postgres`, against a throw-away cluster filled by the PostgreSQL sink of two stations.
#include <gtest/gtest.h>

#include <cstdlib>
#include <thread>

#include <nlohmann/json.hpp>

#include "service/sinks/postgres_results.hpp"
#include "service/sinks/postgres_sink.hpp"
#include "tests/sinks/postgres_cluster.hpp"
#include "tests/sinks/sample_part.hpp"
#include "tests/support/cli/facet_cli.hpp"

namespace facet::sinks_test {
namespace {

using namespace std::chrono_literals;

class CentralResults : public ::testing::Test {
 protected:
  void SetUp() override {
    db_ = std::make_unique<PostgresCluster>(dir_.path());
    for (const std::string station : {"cam1", "cam2"}) {
      config::PostgresSettings s;
      s.enabled = true;
      s.connection = db_->connection();
      s.password = PostgresCluster::kPassword;
      s.outbox.folder = dir_ / (station + "-outbox");
      service::PostgresSink sink(s, station);
      sink.start();
      const std::uint64_t parts = station == "cam1" ? 10 : 3;
      for (std::uint64_t i = 1; i <= parts; ++i) sink.submit(samplePart(i));
      const auto until = std::chrono::steady_clock::now() + 30s;
      while (sink.status().delivered < parts && std::chrono::steady_clock::now() < until)
        std::this_thread::sleep_for(10ms);
      ASSERT_EQ(sink.status().delivered, parts) << sink.status().lastError;
      sink.stop();
    }
  }
  // The connection string a quality engineer would give, the password beside it as libpq reads it.
  std::string withPassword() const {
    return db_->connection() + " password=" + PostgresCluster::kPassword;
  }

  daemon_test::TempDir dir_;
  std::unique_ptr<PostgresCluster> db_;
};

TEST_F(CentralResults, ReadsBackWhatTheSinksWroteOldestFirst) {
  const auto all = service::readPostgresResults(withPassword(), std::nullopt, {});
  ASSERT_EQ(all.size(), 13u);
  for (std::size_t i = 1; i < all.size(); ++i) EXPECT_LE(all[i - 1].part.time, all[i].part.time);
  const auto cam2 = service::readPostgresResults(withPassword(), "cam2", {});
  ASSERT_EQ(cam2.size(), 3u);
  const auto sinceThird =
      service::readPostgresResults(withPassword(), "cam1", samplePart(3).time, 2);
  ASSERT_EQ(sinceThird.size(), 2u);
  EXPECT_EQ(sinceThird[0].part.partId, 3u);

  // Part 7 of cam1, field by field against what was submitted.
  const auto sent = samplePart(7);
  const service::PartResult* got = nullptr;
  for (const auto& s : all)
    if (s.station == "cam1" && s.part.partId == 7) got = &s.part;
  ASSERT_NE(got, nullptr);
  EXPECT_EQ(got->time, sent.time);
  EXPECT_EQ(got->recipeName, sent.recipeName);
  EXPECT_EQ(got->recipeVersion, sent.recipeVersion);
  EXPECT_EQ(got->serial, sent.serial);
  EXPECT_EQ(got->verdict, service::Verdict::Fail);
  EXPECT_EQ(got->failedChecks, sent.failedChecks);
  EXPECT_EQ(got->recordedDefect, "bore_oversize");
  EXPECT_EQ(got->timings.size(), sent.timings.size());
  ASSERT_EQ(got->measurements.size(), 2u);
  EXPECT_EQ(got->measurements[0].name, "bore.diameter");
  EXPECT_DOUBLE_EQ(got->measurements[0].value, 12.07);
  EXPECT_EQ(got->measurements[0].tolPlus, 0.04);
  EXPECT_TRUE(got->measurements[0].checked);
  EXPECT_FALSE(got->measurements[0].pass);
  EXPECT_FALSE(got->measurements[1].nominal.has_value());
  for (const auto& s : all) {
    if (s.part.partId != 5) continue;
    EXPECT_EQ(s.part.notes, samplePart(5).notes) << s.station;
  }
}

TEST_F(CentralResults, FacetResultsExportReadsEveryStationOrOne) {
  ::setenv("PGPASSWORD", PostgresCluster::kPassword, 1);  // as libpq reads it
  const auto json = test::runFacet("results export --postgres '" + db_->connection() + "' --json");
  ASSERT_EQ(json.exitCode, 0) << json.err;
  const auto j = nlohmann::json::parse(json.out);
  EXPECT_EQ(j["count"], 13);
  EXPECT_EQ(j["parts"][0]["station"], "cam1");

  const auto csv =
      test::runFacet("results export --postgres '" + db_->connection() + "' --station cam2 --csv");
  ASSERT_EQ(csv.exitCode, 0) << csv.err;
  EXPECT_EQ(csv.out.rfind("station,part_id,time,", 0), 0u) << csv.out;
  EXPECT_EQ(std::count(csv.out.begin(), csv.out.end(), '\n'), 4) << csv.out;
  EXPECT_NE(csv.out.find("\ncam2,3,"), std::string::npos) << csv.out;

  ::setenv("PGPASSWORD", "wrong", 1);
  const auto refused = test::runFacet("results export --postgres '" + db_->connection() + "'");
  ::unsetenv("PGPASSWORD");
  EXPECT_EQ(refused.exitCode, 1) << refused.out;
  EXPECT_NE(refused.err.find("postgres 127.0.0.1:" + std::to_string(db_->port()) +
                             "/facet: cannot connect"),
            std::string::npos)
      << refused.err;
  EXPECT_EQ(refused.err.find("wrong"), std::string::npos) << refused.err;
}

TEST(CentralResultsCli, StationWithoutPostgresAndNeitherSourceAreRefused) {
  const auto station = test::runFacet("results export --db x.db --station cam1");
  EXPECT_NE(station.exitCode, 0);
  EXPECT_NE(station.err.find("--postgres"), std::string::npos) << station.err;
  const auto neither = test::runFacet("results export --json");
  EXPECT_EQ(neither.exitCode, 1);
  EXPECT_NE(neither.err.find("needs --db FILE or --postgres"), std::string::npos) << neither.err;
}

// libpq is loaded when first used: a command that needs no database starts without it (and the 20
// libraries it brings), and where it cannot be loaded the command that needs it says so.
TEST(CentralResultsCli, LibpqIsLoadedOnlyByTheCommandsThatUseIt) {
  const auto version = test::runFacet("version");
  ASSERT_EQ(version.exitCode, 0) << version.err;
  ::setenv("LD_DEBUG", "files", 1);  // the loader lists every library it opens on stderr
  const auto traced = test::runFacet("version");
  ::unsetenv("LD_DEBUG");
  ASSERT_NE(traced.err.find("libopencv_core"), std::string::npos) << "no loader trace";
  EXPECT_EQ(traced.err.find("libpq"), std::string::npos) << "facet version loaded libpq";

  ::setenv("FACET_LIBPQ", "/nonexistent/libpq.so.5", 1);
  const auto missing = test::runFacet("results export --postgres 'host=127.0.0.1 dbname=x'");
  ::unsetenv("FACET_LIBPQ");
  EXPECT_EQ(missing.exitCode, 1) << missing.out;
  EXPECT_NE(missing.err.find("PostgreSQL's client library cannot be loaded"), std::string::npos)
      << missing.err;
  EXPECT_NE(missing.err.find("/nonexistent/libpq.so.5"), std::string::npos) << missing.err;
}

}  // namespace
}  // namespace facet::sinks_test
