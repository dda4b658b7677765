// Outbox: order, restart, quota, interrupted writes; and the fleet message round trip.
#include <gtest/gtest.h>

#include <fstream>

#include <nlohmann/json.hpp>

#include "service/sinks/fleet_message.hpp"
#include "service/sinks/outbox.hpp"
#include "tests/daemon/child_process.hpp"
#include "tests/sinks/sample_part.hpp"

namespace facet::sinks_test {
namespace {

using service::Outbox;

std::vector<std::string> payloads(const std::vector<service::OutboxRecord>& records) {
  std::vector<std::string> out;
  for (const auto& r : records) out.push_back(r.payload);
  return out;
}

TEST(Outbox, KeepsOrderAcrossARestartAndForgetsWhatWasDelivered) {
  daemon_test::TempDir dir;
  {
    Outbox box(dir / "o", 1 << 20, "test outbox");
    for (int i = 1; i <= 5; ++i) ASSERT_TRUE(box.append("r" + std::to_string(i)));
    const auto first = box.peek(2);
    ASSERT_EQ(payloads(first), (std::vector<std::string>{"r1", "r2"}));
    box.remove({first[0].seq, first[1].seq});
    EXPECT_EQ(box.stats().pending, 3u);
  }
  // An interrupted write leaves a temporary file that is never taken for a record.
  std::ofstream(dir / "o/00000000000000000099.json.tmp") << "half";
  Outbox again(dir / "o", 1 << 20, "test outbox");
  EXPECT_EQ(again.stats().recovered, 3u);
  ASSERT_TRUE(again.append("r6"));
  EXPECT_EQ(payloads(again.peek(10)), (std::vector<std::string>{"r3", "r4", "r5", "r6"}));
  EXPECT_FALSE(std::filesystem::exists(dir / "o/00000000000000000099.json.tmp"));
}

TEST(Outbox, FullQuotaDropsTheOldestAndCountsThem) {
  daemon_test::TempDir dir;
  Outbox box(dir / "o", 100, "test outbox");  // ten 10-byte records
  for (int i = 0; i < 25; ++i) {
    char record[16];
    std::snprintf(record, sizeof record, "record-%03d", i);
    ASSERT_TRUE(box.append(record));
  }
  const auto s = box.stats();
  EXPECT_EQ(s.pending, 10u);
  EXPECT_EQ(s.dropped, 15u);
  EXPECT_LE(s.bytes, 100u);
  const auto left = box.peek(100);
  ASSERT_EQ(left.size(), 10u);
  EXPECT_EQ(left.front().payload, "record-015");
  EXPECT_EQ(left.back().payload, "record-024");
  // Files on disk match the count.
  std::size_t files = 0;
  for ([[maybe_unused]] const auto& e : std::filesystem::directory_iterator(dir / "o")) ++files;
  EXPECT_EQ(files, 10u);
}

TEST(Outbox, AFolderThatCannotBeWrittenIsCountedNotThrown) {
  daemon_test::TempDir dir;
  Outbox box(dir / "o", 1 << 20, "test outbox");
  std::filesystem::remove_all(dir / "o");
  EXPECT_FALSE(box.append("lost"));
  EXPECT_EQ(box.stats().writeErrors, 1u);
  EXPECT_EQ(box.stats().pending, 0u);
}

TEST(FleetMessage, RoundTripsThePart) {
  const auto part = samplePart(14);
  std::string station;
  const auto back = service::partFromFleetMessage(
      nlohmann::json::parse(service::fleetMessage("cam1", part).dump()), &station);
  EXPECT_EQ(station, "cam1");
  EXPECT_EQ(back.partId, part.partId);
  EXPECT_EQ(back.time, part.time);
  EXPECT_EQ(back.recipeVersion, part.recipeVersion);
  EXPECT_EQ(back.verdict, part.verdict);
  EXPECT_EQ(back.failedChecks, part.failedChecks);
  EXPECT_EQ(back.recordedDefect, "bore_oversize");
  EXPECT_EQ(
      service::partFromFleetMessage(
          nlohmann::json::parse(service::fleetMessage("cam1", samplePart(5)).dump()), &station)
          .notes,
      samplePart(5).notes);
  ASSERT_EQ(back.measurements.size(), 2u);
  const auto& d = back.measurements.front();
  EXPECT_EQ(d.name, "bore.diameter");
  EXPECT_DOUBLE_EQ(d.value, 12.07);
  EXPECT_EQ(d.tolMinus, 0.05);
  EXPECT_EQ(d.tolPlus, 0.04);
  EXPECT_TRUE(d.checked);
  EXPECT_FALSE(back.measurements.back().checked);
  // A message queued before parts had a defect reads as a part without one.
  auto old = service::fleetMessage("cam1", part);
  old.erase("defect");
  old.erase("notes");
  EXPECT_EQ(service::partFromFleetMessage(old, &station).recordedDefect, "");
  EXPECT_TRUE(service::partFromFleetMessage(old, &station).notes.empty());
  EXPECT_THROW(service::partFromFleetMessage(nlohmann::json{{"station", "x"}}, &station),
               std::runtime_error);
}

}  // namespace
}  // namespace facet::sinks_test
