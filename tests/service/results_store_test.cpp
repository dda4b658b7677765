#include <filesystem>

#include <gtest/gtest.h>
#include <sqlite3.h>

#include "service/daemon/results_store.hpp"

namespace facet::service {
namespace {

namespace fs = std::filesystem;

fs::path freshFile(const std::string& name) {
  const fs::path dir = fs::temp_directory_path() / ("facet-store-" + std::to_string(::getpid()));
  fs::create_directories(dir);
  const fs::path f = dir / name;
  fs::remove(f);
  fs::remove(f.string() + "-wal");
  fs::remove(f.string() + "-shm");
  return f;
}

// Rows in the measurements table, counted through a connection of the test's own.
std::int64_t measurementRows(const fs::path& file) {
  sqlite3* db = nullptr;
  sqlite3_open_v2(file.c_str(), &db, SQLITE_OPEN_READONLY, nullptr);
  sqlite3_stmt* s = nullptr;
  std::int64_t rows = -1;
  if (sqlite3_prepare_v2(db, "SELECT COUNT(*) FROM measurements", -1, &s, nullptr) == SQLITE_OK &&
      sqlite3_step(s) == SQLITE_ROW)
    rows = sqlite3_column_int64(s, 0);
  sqlite3_finalize(s);
  sqlite3_close(db);
  return rows;
}

PartResult part(std::uint64_t id, Verdict v, double diameter) {
  PartResult p;
  p.partId = id;
  p.time = std::chrono::system_clock::now();
  p.recipeId = 3;
  p.recipeName = "bracket";
  p.recipeVersion = "abc123";
  p.frameId = 100 + id;
  p.serial = "SN" + std::to_string(id);
  p.verdict = v;
  p.measurements.push_back(
      {"bore.diameter", diameter, "mm", 10.0, 0.05, 0.05, true, std::abs(diameter - 10.0) <= 0.05});
  p.measurements.push_back({"align.score", 0.93, "score", {}, {}, {}, false, true});
  p.timings.push_back({"bore", 0.8});
  if (v == Verdict::Fail) p.failedChecks.push_back("bore.diameter");
  if (v == Verdict::Fail) p.expectedVerdict = "fail", p.recordedDefect = "bore 10.2 mm";
  return p;
}

TEST(ResultsStore, StoresAndReadsBackEveryField) {
  const fs::path file = freshFile("a.sqlite");
  ResultsStore store(file);
  store.store(part(1, Verdict::Pass, 10.01));
  store.store(part(2, Verdict::Fail, 10.2));
  EXPECT_EQ(store.partCount(), 2);
  EXPECT_EQ(store.lastPartId(), 2u);
  const auto parts = store.latest(10);
  ASSERT_EQ(parts.size(), 2u);
  EXPECT_EQ(parts[1].verdict, Verdict::Fail);
  EXPECT_EQ(parts[1].serial, "SN2");
  EXPECT_EQ(parts[1].failedChecks, std::vector<std::string>{"bore.diameter"});
  ASSERT_EQ(parts[1].measurements.size(), 2u);
  EXPECT_DOUBLE_EQ(parts[1].measurements[0].value, 10.2);
  EXPECT_FALSE(parts[1].measurements[0].pass);
  EXPECT_FALSE(parts[1].measurements[1].nominal.has_value());
  EXPECT_EQ(parts[0].timings.at(0).step, "bore");
  EXPECT_EQ(parts[1].expectedVerdict, "fail");
  EXPECT_EQ(parts[1].recordedDefect, "bore 10.2 mm");
  EXPECT_EQ(parts[0].recordedDefect, "");
  EXPECT_EQ(toJson(parts[1]).at("defect"), "bore 10.2 mm");
  EXPECT_EQ(store.integrityCheck(), "ok");
}

TEST(ResultsStore, KeepsTheStepsNotes) {
  const fs::path file = freshFile("notes.sqlite");
  ResultsStore store(file);
  auto p = part(1, Verdict::Pass, 10.0);
  p.notes = {"edge: part of the caliper lies outside the image: measured inside only",
             "bore: found off its nominal place"};
  store.store(p);
  store.store(part(2, Verdict::Pass, 10.0));
  const auto parts = store.latest(10);
  ASSERT_EQ(parts.size(), 2u);
  EXPECT_EQ(parts[0].notes, p.notes);
  EXPECT_TRUE(parts[1].notes.empty());
  EXPECT_EQ(toJson(parts[0]).at("notes").size(), 2u);
}

// A store written before parts had the recorded defect and notes: opened, it gains the columns,
// keeps its parts (defect '') and stores new ones with theirs.
TEST(ResultsStore, StoreWithoutTheDefectColumnGainsItAndKeepsItsParts) {
  const fs::path file = freshFile("old.sqlite");
  {
    ResultsStore store(file);
    store.store(part(1, Verdict::Pass, 10.0));
  }
  {
    sqlite3* db = nullptr;
    ASSERT_EQ(sqlite3_open(file.c_str(), &db), SQLITE_OK);
    ASSERT_EQ(sqlite3_exec(db, "ALTER TABLE parts DROP COLUMN defect", nullptr, nullptr, nullptr),
              SQLITE_OK)
        << sqlite3_errmsg(db);
    ASSERT_EQ(sqlite3_exec(db, "ALTER TABLE parts DROP COLUMN notes", nullptr, nullptr, nullptr),
              SQLITE_OK)
        << sqlite3_errmsg(db);
    sqlite3_close(db);
  }
  ResultsStore store(file);
  store.store(part(2, Verdict::Fail, 10.2));
  const auto parts = store.latest(10);
  ASSERT_EQ(parts.size(), 2u);
  EXPECT_EQ(parts[0].serial, "SN1");
  EXPECT_EQ(parts[0].recordedDefect, "");
  EXPECT_EQ(parts[1].recordedDefect, "bore 10.2 mm");
  EXPECT_EQ(store.integrityCheck(), "ok");
}

TEST(ResultsStore, DuplicatePartIdIsRefusedAndNothingHalfWritten) {
  const fs::path file = freshFile("b.sqlite");
  ResultsStore store(file);
  store.store(part(1, Verdict::Pass, 10.0));
  EXPECT_THROW(store.store(part(1, Verdict::Fail, 11.0)), std::runtime_error);
  EXPECT_EQ(store.partCount(), 1);
  EXPECT_EQ(store.latest(1).at(0).measurements.at(0).value, 10.0);
}

TEST(ResultsStore, RetentionKeepsNewestParts) {
  const fs::path file = freshFile("c.sqlite");
  ResultsStore store(file, {.maxAge = std::nullopt, .maxParts = 3});
  for (std::uint64_t i = 1; i <= 5; ++i) store.store(part(i, Verdict::Pass, 10.0));
  EXPECT_EQ(store.applyRetention(std::chrono::system_clock::now()), 2);
  EXPECT_EQ(store.partCount(), 3);
  EXPECT_EQ(store.latest(10).front().partId, 3u);
}

TEST(ResultsStore, RetentionByAgeDeletesOldPartsAndTheirMeasurementsButKeepsTheNewest) {
  const fs::path file = freshFile("age.sqlite");
  ResultsStore store(file, {.maxAge = std::chrono::hours(24), .maxParts = std::nullopt});
  const auto now = std::chrono::system_clock::now();
  for (std::uint64_t i = 1; i <= 4; ++i) {
    PartResult p = part(i, Verdict::Pass, 10.0);
    p.time = now - std::chrono::hours(i <= 2 ? 48 : 1);  // parts 1 and 2 are two days old
    store.store(p);
  }
  EXPECT_EQ(store.applyRetention(now), 2);
  EXPECT_EQ(store.partCount(), 2);
  EXPECT_EQ(store.latest(10).front().partId, 3u);  // oldest first
  EXPECT_EQ(measurementRows(file), 4);  // two parts' measurements went with them (foreign key)

  // A week later every part is old, but the newest stays so that part ids continue after it.
  EXPECT_EQ(store.applyRetention(now + std::chrono::hours(24 * 7)), 1);
  EXPECT_EQ(store.partCount(), 1);
  EXPECT_EQ(store.lastPartId(), 4u);
}

TEST(ResultsStore, RetentionInSlicesDeletesOldestFirstUpToTheLimit) {
  const fs::path file = freshFile("slices.sqlite");
  ResultsStore store(file, {.maxAge = std::chrono::hours(24), .maxParts = 10});
  const auto now = std::chrono::system_clock::now();
  for (std::uint64_t i = 1; i <= 30; ++i) {
    PartResult p = part(i, Verdict::Pass, 10.0);
    p.time = now - std::chrono::hours(i <= 6 ? 48 : 1);  // parts 1-6 are two days old
    store.store(p);
  }
  // 6 too old, then 14 more beyond the newest 10: 20 in slices of 4, oldest first.
  std::vector<std::int64_t> slices;
  std::vector<std::uint64_t> oldestLeft;
  for (int k = 0; k < 8; ++k) {
    slices.push_back(store.applyRetention(now, 4));
    oldestLeft.push_back(store.latest(100).front().partId);
  }
  EXPECT_EQ(slices, (std::vector<std::int64_t>{4, 4, 4, 4, 4, 0, 0, 0}));
  EXPECT_EQ(oldestLeft, (std::vector<std::uint64_t>{5, 9, 13, 17, 21, 21, 21, 21}));
  EXPECT_EQ(store.partCount(), 10);
  EXPECT_EQ(measurementRows(file), 20);  // two per part, for the ten left
}

TEST(ResultsStore, ReopenContinuesAfterLastPart) {
  const fs::path file = freshFile("d.sqlite");
  { ResultsStore(file).store(part(41, Verdict::Pass, 10.0)); }
  ResultsStore again(file);
  EXPECT_EQ(again.lastPartId(), 41u);
}

// A page is the `limit` parts right after the given id, oldest first, with their measurements,
// not the newest ones: paging with the last id received visits every part once.
TEST(ResultsStore, PartsAfterIsTheNextPageOldestFirst) {
  const fs::path file = freshFile("paging.sqlite");
  ResultsStore store(file);
  for (std::uint64_t id = 1; id <= 30; ++id) store.store(part(id, Verdict::Pass, 10.0));
  const auto page = store.partsAfter(4, 5);
  ASSERT_EQ(page.size(), 5u);
  for (std::size_t i = 0; i < page.size(); ++i) {
    EXPECT_EQ(page[i].partId, 5 + i);
    EXPECT_EQ(page[i].measurements.size(), 2u);
  }
  std::vector<std::uint64_t> seen;
  for (std::uint64_t after = 0;;) {
    const auto next = store.partsAfter(after, 7);
    if (next.empty()) break;
    for (const auto& p : next) seen.push_back(p.partId);
    after = next.back().partId;
    if (after == 14) store.store(part(31, Verdict::Fail, 11.0));  // arrives while paging
  }
  ASSERT_EQ(seen.size(), 31u);
  for (std::size_t i = 0; i < seen.size(); ++i) EXPECT_EQ(seen[i], i + 1);
  EXPECT_TRUE(store.partsAfter(31, 7).empty());
}

TEST(ResultsStore, UnwritableLocationNamesTheFile) {
  try {
    ResultsStore store("/proc/facet-no-such/results.sqlite");
    FAIL() << "expected an error";
  } catch (const std::exception& e) {
    EXPECT_NE(std::string(e.what()).find("/proc/facet-no-such"), std::string::npos) << e.what();
  }
}

TEST(ResultsExport, CsvHasOneColumnPerMeasurement) {
  auto recorded = part(2, Verdict::Fail, 10.2);
  recorded.expectedVerdict = "fail";
  recorded.recordedDefect = "bore, oversize";  // a comma: quoted
  const std::string csv = toCsv({part(1, Verdict::Pass, 10.01), recorded});
  EXPECT_NE(csv.find("inspection_ms,expected_verdict,defect,bore.diameter,align.score"),
            std::string::npos)
      << csv;
  EXPECT_NE(csv.find(",fail,\"bore, oversize\","), std::string::npos) << csv;
  EXPECT_NE(csv.find(",fail,bore.diameter,"), std::string::npos) << csv;
  const auto j = toJson(part(2, Verdict::Fail, 10.2));
  EXPECT_EQ(j["verdict"], "fail");
  EXPECT_EQ(j["values"]["bore.diameter"]["nominal"], 10.0);
}

}  // namespace
}  // namespace facet::service
