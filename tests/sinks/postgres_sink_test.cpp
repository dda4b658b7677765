// PostgresSink against a throw-away PostgreSQL cluster made by the test.
#include <gtest/gtest.h>

#include <cstdio>
#include <thread>

#include "service/sinks/postgres_sink.hpp"
#include "tests/sinks/postgres_cluster.hpp"
#include "tests/sinks/sample_part.hpp"

namespace facet::sinks_test {
namespace {

using namespace std::chrono_literals;
using service::PostgresSink;

config::PostgresSettings settingsFor(const PostgresCluster& db, const std::string& folder) {
  config::PostgresSettings s;
  s.enabled = true;
  s.connection = db.connection();
  s.password = PostgresCluster::kPassword;
  s.reconnectMaxMs = 400;
  s.outbox.folder = folder + "/pg-outbox";
  return s;
}

bool waitUntil(const std::function<bool()>& done, std::chrono::milliseconds timeout) {
  const auto until = std::chrono::steady_clock::now() + timeout;
  while (!done()) {
    if (std::chrono::steady_clock::now() > until) return false;
    std::this_thread::sleep_for(10ms);
  }
  return true;
}

TEST(PostgresSink, WritesTheResultsStoreTablesWithTheStation) {
  daemon_test::TempDir dir;
  PostgresCluster db(dir.path());
  PostgresSink sink(settingsFor(db, dir.path()), "cam1");
  sink.start();
  for (std::uint64_t i = 1; i <= 10; ++i) sink.submit(samplePart(i));
  ASSERT_TRUE(waitUntil([&] { return sink.status().delivered == 10; }, 30s))
      << sink.status().lastError;
  EXPECT_EQ(db.query("SELECT count(*) FROM parts WHERE station = 'cam1'"), "10");
  EXPECT_EQ(db.query("SELECT count(*) FROM measurements"), "20");
  EXPECT_EQ(db.query("SELECT verdict || ' ' || failed_checks || ' ' || serial || ' ' || "
                     "recipe_name || ' ' || recipe_version || ' ' || defect "
                     "FROM parts WHERE part_id = 7"),
            "fail bore.diameter SN7 flange 9c1e55aa bore_oversize");
  EXPECT_EQ(db.query("SELECT count(*) FROM parts WHERE defect = ''"), "9");
  EXPECT_EQ(db.query("SELECT notes FROM parts WHERE part_id = 5"),
            "locate: found off its nominal place");
  EXPECT_EQ(db.query("SELECT value || ' ' || unit || ' ' || nominal || ' ' || tol_minus || ' ' || "
                     "tol_plus || ' ' || checked || ' ' || pass FROM measurements "
                     "WHERE part_id = 7 AND name = 'bore.diameter'"),
            "12.07 mm 12 0.05 0.04 true false");
  EXPECT_EQ(db.query("SELECT time_us FROM parts WHERE part_id = 1"),
            std::to_string(1795986187125331LL + 1000));
  EXPECT_EQ(db.query("SELECT to_char(time_utc AT TIME ZONE 'UTC', 'YYYY-MM-DD HH24:MI:SS.US') "
                     "FROM parts WHERE part_id = 1"),
            "2026-11-29 21:03:07.126331");

  // The same parts again (as after a COMMIT whose answer was lost): nothing is written twice.
  for (std::uint64_t i = 1; i <= 10; ++i) sink.submit(samplePart(i));
  ASSERT_TRUE(waitUntil([&] { return sink.status().delivered == 20; }, 30s));
  EXPECT_EQ(db.query("SELECT count(*) FROM parts"), "10");
  EXPECT_EQ(db.query("SELECT count(*) FROM measurements"), "20");
}

// 1,000 parts; the server is killed (SIGKILL) and restarted twice, and facetd's sink itself is
// stopped and recreated on its outbox in the second outage: no part lost, none twice.
TEST(PostgresSink, ServerKilledTwiceAndStationRestartedLoseAndRepeatNothing) {
  daemon_test::TempDir dir;
  PostgresCluster db(dir.path());
  const auto settings = settingsFor(db, dir.path());
  auto sink = std::make_unique<PostgresSink>(settings, "cam1");
  sink->start();
  ASSERT_TRUE(waitUntil([&] { return sink->status().connected; }, 30s)) << sink->status().lastError;
  constexpr int kParts = 1000;
  std::uint64_t buffered1 = 0, buffered2 = 0, recovered = 0;
  for (int i = 1; i <= kParts; ++i) {
    if (i == 250 || i == 600) db.kill();
    if (i == 400) {
      buffered1 = sink->status().outbox.pending;
      db.start();
    }
    if (i == 700) {
      // facetd restarts while the database is still down: its outbox stays on disk.
      sink->stop(0ms);
      sink = std::make_unique<PostgresSink>(settings, "cam1");
      recovered = sink->status().outbox.recovered;
      sink->start();
    }
    if (i == 800) {
      buffered2 = sink->status().outbox.pending;
      db.start();
    }
    sink->submit(samplePart(static_cast<std::uint64_t>(i)));
    std::this_thread::sleep_for(2ms);
  }
  ASSERT_TRUE(waitUntil([&] { return sink->status().outbox.pending == 0; }, 60s))
      << sink->status().outbox.pending << " still waiting: " << sink->status().lastError;
  EXPECT_EQ(db.query("SELECT count(*) FROM parts"), std::to_string(kParts));
  EXPECT_EQ(db.query("SELECT count(DISTINCT part_id) FROM parts"), std::to_string(kParts));
  EXPECT_EQ(db.query("SELECT min(part_id) || '-' || max(part_id) FROM parts"), "1-1000");
  EXPECT_EQ(db.query("SELECT count(*) FROM measurements"), std::to_string(2 * kParts));
  EXPECT_EQ(sink->status().outbox.dropped, 0u);
  EXPECT_GT(buffered1, 0u);
  EXPECT_GT(recovered, 0u);
  EXPECT_GT(buffered2, recovered);
  std::printf(
      "outage 1 (parts 250-400): %llu parts buffered, all written after the restart\n"
      "outage 2 (parts 600-800, facetd's sink restarted at 700): %llu taken over from "
      "disk, %llu buffered at the server's restart, all written\n",
      static_cast<unsigned long long>(buffered1), static_cast<unsigned long long>(recovered),
      static_cast<unsigned long long>(buffered2));
}

TEST(PostgresSink, WrongPasswordIsAClearErrorAndKeepsTheResults) {
  daemon_test::TempDir dir;
  PostgresCluster db(dir.path());
  auto settings = settingsFor(db, dir.path());
  settings.password = "not-the-password";
  PostgresSink sink(settings, "cam1");
  sink.start();
  sink.submit(samplePart(1));
  ASSERT_TRUE(
      waitUntil([&] { return sink.status().lastError.find("password") != std::string::npos; }, 20s))
      << sink.status().lastError;
  const auto s = sink.status();
  EXPECT_TRUE(s.degraded());
  EXPECT_NE(s.lastError.find("password authentication failed"), std::string::npos) << s.lastError;
  EXPECT_NE(s.lastError.find("postgres.password"), std::string::npos) << s.lastError;
  EXPECT_EQ(s.outbox.pending, 1u);
}

TEST(PostgresSink, DatabaseDownAtStartBuffersUntilItIsThere) {
  daemon_test::TempDir dir;
  PostgresCluster db(dir.path());
  db.kill();
  PostgresSink sink(settingsFor(db, dir.path()), "cam1");
  sink.start();
  for (std::uint64_t i = 1; i <= 30; ++i) sink.submit(samplePart(i));
  ASSERT_TRUE(waitUntil(
      [&] { return sink.status().lastError.find("cannot connect") != std::string::npos; }, 20s));
  EXPECT_TRUE(sink.status().degraded());
  EXPECT_EQ(sink.status().outbox.pending, 30u);
  db.start();
  ASSERT_TRUE(waitUntil([&] { return sink.status().delivered == 30; }, 30s))
      << sink.status().lastError;
  EXPECT_EQ(db.query("SELECT count(*) FROM parts"), "30");
  EXPECT_FALSE(sink.status().degraded());
}

// A database written by an earlier facetd, whose parts table has no `defect` and `notes`, gains
// the columns and keeps its rows.
TEST(PostgresSink, ADatabaseFromBeforeDefectGainsTheColumn) {
  daemon_test::TempDir dir;
  PostgresCluster db(dir.path());
  ASSERT_EQ(
      db.query(
          "CREATE TABLE parts (station TEXT NOT NULL, part_id BIGINT NOT NULL, time_us BIGINT NOT "
          "NULL, time_utc TIMESTAMPTZ NOT NULL, recipe_id INTEGER NOT NULL, recipe_name TEXT NOT "
          "NULL, recipe_version TEXT NOT NULL, frame_id BIGINT NOT NULL, source TEXT NOT NULL, "
          "serial "
          "TEXT NOT NULL, expected TEXT NOT NULL, verdict TEXT NOT NULL, failed_checks TEXT NOT "
          "NULL, "
          "error TEXT NOT NULL, inspection_ms DOUBLE PRECISION NOT NULL, timings_json TEXT NOT "
          "NULL, "
          "PRIMARY KEY (station, part_id, time_us)); INSERT INTO parts VALUES ('old', 1, 0, now(), "
          "1, "
          "'r', 'v', 1, 's', '', '', 'pass', '', '', 1.0, '[]'); SELECT 1"),
      "1");
  PostgresSink sink(settingsFor(db, dir.path()), "cam1");
  sink.start();
  sink.submit(samplePart(7));
  ASSERT_TRUE(waitUntil([&] { return sink.status().delivered == 1; }, 30s))
      << sink.status().lastError;
  EXPECT_EQ(
      db.query("SELECT string_agg(station || ':' || defect || ':' || notes, ' ' ORDER BY station) "
               "FROM parts"),
      "cam1:bore_oversize: old::");
}

}  // namespace
}  // namespace facet::sinks_test
