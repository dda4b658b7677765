#include <filesystem>
#include <fstream>
#include <string>

#include <gtest/gtest.h>
#include <opencv2/imgcodecs.hpp>

#include "service/daemon/image_archive.hpp"
#include "service/daemon/metrics.hpp"
#include "tests/service/archived_parts.hpp"

namespace facet::service {
namespace {

namespace fs = std::filesystem;

TEST(Metrics, ExpositionFormat) {
  MetricsRegistry m;
  m.counter("facet_parts_total", "Parts inspected", "verdict=\"pass\"").increment();
  m.counter("facet_parts_total", "Parts inspected", "verdict=\"pass\"").increment(2);
  m.gauge("facet_queue_depth", "Frames waiting", "queue=\"inspect\"").set(4);
  auto& h = m.histogram("facet_stage_ms", "Stage latency", {1, 10}, "stage=\"inspect\"");
  h.observe(0.5);
  h.observe(5);
  h.observe(50);
  const std::string text = m.exposition();
  EXPECT_NE(text.find("# TYPE facet_parts_total counter"), std::string::npos);
  EXPECT_NE(text.find("facet_parts_total{verdict=\"pass\"} 3"), std::string::npos) << text;
  EXPECT_NE(text.find("facet_queue_depth{queue=\"inspect\"} 4"), std::string::npos);
  EXPECT_NE(text.find("facet_stage_ms_bucket{stage=\"inspect\",le=\"1\"} 1"), std::string::npos);
  EXPECT_NE(text.find("facet_stage_ms_bucket{stage=\"inspect\",le=\"10\"} 2"), std::string::npos);
  EXPECT_NE(text.find("facet_stage_ms_bucket{stage=\"inspect\",le=\"+Inf\"} 3"), std::string::npos);
  EXPECT_NE(text.find("facet_stage_ms_count{stage=\"inspect\"} 3"), std::string::npos);
  EXPECT_THROW(m.gauge("facet_parts_total", "x"), std::logic_error);
}

using test::partWith;

TEST(ImageArchive, KeepsFailedPartsAndSampleOfGoodOnesUnderQuota) {
  const fs::path dir = fs::temp_directory_path() / ("facet-archive-" + std::to_string(::getpid()));
  fs::remove_all(dir);
  cv::Mat noise(200, 200, CV_8U);
  cv::randu(noise, 0, 255);  // incompressible: ~40 KB per PNG
  ImageArchive archive({.folder = dir, .quotaBytes = 200'000, .failed = true, .goodEvery = 2});
  EXPECT_FALSE(archive.archive(partWith(1, Verdict::Pass), noise, noise));  // 1st good: skipped
  EXPECT_TRUE(archive.archive(partWith(2, Verdict::Pass), noise, noise));   // 2nd good: kept
  for (std::uint64_t i = 3; i < 10; ++i) {
    const auto saved = archive.archive(partWith(i, Verdict::Fail), noise, noise);
    ASSERT_TRUE(saved);
    EXPECT_TRUE(fs::exists(saved->raw));
    EXPECT_TRUE(fs::exists(saved->overlay));
  }
  EXPECT_LE(archive.bytesUsed(), 200'000u);
  EXPECT_GT(archive.filesRemoved(), 0u);
  std::uint64_t onDisk = 0;
  for (const auto& e : fs::recursive_directory_iterator(dir))
    if (e.is_regular_file()) onDisk += e.file_size();
  EXPECT_EQ(onDisk, archive.bytesUsed());
  EXPECT_FALSE(archive.degraded());
  // A restarted archive counts the files already there.
  ImageArchive again({.folder = dir, .quotaBytes = 200'000});
  EXPECT_EQ(again.bytesUsed(), onDisk);
  fs::remove_all(dir);
}

// Whether this process has mapped the image-codec module (camera/image_codecs.hpp).
bool codecModuleLoaded() {
  std::ifstream maps("/proc/self/maps");
  std::string line;
  while (std::getline(maps, line))
    if (line.find("libfacet_image_codecs") != std::string::npos) return true;
  return false;
}

// The archive's PNGs are encoded in the process (camera/png_writer.hpp): loading the codec module
// for the first failed part took 0.4 s on the publishing thread, and the PLC results of the parts
// behind it waited (bench_daemon's changeover rows, "longest wait between results").
TEST(ImageArchive, WritesItsPngsWithoutLoadingTheCodecModule) {
  if (codecModuleLoaded())
    GTEST_SKIP()
        << "an earlier test of this process loaded the module (ctest runs each test alone)";
  const fs::path dir =
      fs::temp_directory_path() / ("facet-archive-png-" + std::to_string(::getpid()));
  fs::remove_all(dir);
  cv::Mat frame(48, 64, CV_8U), overlay(48, 64, CV_8UC3);
  cv::randu(frame, 0, 255);
  cv::randu(overlay, 0, 255);
  ImageArchive archive({.folder = dir});
  const auto saved = archive.archive(partWith(3, Verdict::Fail), frame, overlay);
  ASSERT_TRUE(saved);
  EXPECT_FALSE(codecModuleLoaded());
  // OpenCV reads back the very pixels (cv::imread here is the test's own, linked directly).
  EXPECT_EQ(cv::norm(cv::imread(saved->raw.string(), cv::IMREAD_UNCHANGED), frame, cv::NORM_INF),
            0);
  EXPECT_EQ(
      cv::norm(cv::imread(saved->overlay.string(), cv::IMREAD_UNCHANGED), overlay, cv::NORM_INF),
      0);
  fs::remove_all(dir);
}

TEST(ImageArchive, StartRemovesPartialFilesOfAnInterruptedWrite) {
  const fs::path dir =
      fs::temp_directory_path() / ("facet-archive-partial-" + std::to_string(::getpid()));
  fs::create_directories(dir / "20261122");
  std::ofstream(dir / "20261122/part-7-fail.png.partial") << "\x89PNG half a file";
  cv::Mat img(10, 10, CV_8U, cv::Scalar(1));
  ImageArchive archive({.folder = dir});
  EXPECT_FALSE(fs::exists(dir / "20261122/part-7-fail.png.partial"));
  EXPECT_EQ(archive.bytesUsed(), 0u);
  const auto saved = archive.archive(partWith(7, Verdict::Fail), img, img);
  ASSERT_TRUE(saved);
  EXPECT_FALSE(cv::imread(saved->raw.string(), cv::IMREAD_UNCHANGED).empty());
  fs::remove_all(dir);
}

TEST(ImageArchive, UnwritableFolderIsDegradedNotFatal) {
  cv::Mat img(10, 10, CV_8U, cv::Scalar(1));
  ImageArchive archive({.folder = "/proc/facet-archive"});
  EXPECT_FALSE(archive.archive(partWith(1, Verdict::Fail), img, img));
  EXPECT_TRUE(archive.degraded());
  EXPECT_FALSE(archive.lastError().empty());
}

}  // namespace
}  // namespace facet::service
