// The image archive's writes on their own thread (service/daemon/archive_writer.hpp): the caller
// never waits for the disk, what is queued reaches it, and a burst beyond the queue drops the
// oldest waiting part's pictures, counted.
#include "service/daemon/archive_writer.hpp"

#include <gtest/gtest.h>
#include <unistd.h>

#include <atomic>
#include <chrono>
#include <filesystem>
#include <future>
#include <thread>

#include "tests/service/archived_parts.hpp"

namespace facet::service {
namespace {

namespace fs = std::filesystem;

int pngsOfPart(const fs::path& dir, std::uint64_t id) {
  int n = 0;
  if (!fs::exists(dir)) return 0;
  const std::string stem = "part-" + std::to_string(id) + "-";
  for (const auto& e : fs::recursive_directory_iterator(dir))
    if (e.is_regular_file() && e.path().filename().string().starts_with(stem)) ++n;
  return n;
}

struct Folder {
  fs::path path =
      fs::temp_directory_path() /
      ("facet-archive-writer-" + std::to_string(::getpid()) + "-" + std::to_string(counter++));
  Folder() { fs::remove_all(path); }
  ~Folder() { fs::remove_all(path); }
  static inline int counter = 0;
};

TEST(ArchiveWriter, WritesWhatThePolicyKeepsOffTheCallersThread) {
  const Folder dir;
  ImageArchive archive({.folder = dir.path, .failed = true, .goodEvery = 0});
  MetricsRegistry metrics;
  ArchiveWriter writer(archive, metrics, 4);
  const cv::Mat frame(32, 48, CV_8U, cv::Scalar(90));
  std::atomic<std::thread::id> drawnOn;
  writer.submit(test::partWith(1, Verdict::Fail), frame, [&] {
    drawnOn = std::this_thread::get_id();
    return cv::Mat(32, 48, CV_8UC3, cv::Scalar(1, 2, 3));
  });
  writer.submit(test::partWith(2, Verdict::Pass), frame, [] { return cv::Mat(); });  // not kept
  writer.flush();
  EXPECT_EQ(pngsOfPart(dir.path, 1), 2) << "the frame and its overlay";
  EXPECT_EQ(pngsOfPart(dir.path, 2), 0);
  EXPECT_NE(drawnOn.load(), std::this_thread::get_id()) << "drawn on the writer's thread";
}

TEST(ArchiveWriter, ABurstBeyondTheQueueDropsTheOldestWaitingPartAndCountsIt) {
  const Folder dir;
  ImageArchive archive({.folder = dir.path});
  MetricsRegistry metrics;
  ArchiveWriter writer(archive, metrics, 2);
  const cv::Mat frame(16, 16, CV_8U, cv::Scalar(7));
  // The first part's overlay holds the writer until released: a disk that has stalled.
  std::promise<void> release;
  std::shared_future<void> released = release.get_future().share();
  std::promise<void> started;
  writer.submit(test::partWith(1, Verdict::Fail), frame, [&] {
    started.set_value();
    released.wait();
    return cv::Mat();
  });
  started.get_future().wait();
  const auto t0 = std::chrono::steady_clock::now();
  for (std::uint64_t id = 2; id <= 5; ++id)
    writer.submit(test::partWith(id, Verdict::Fail), frame, [] { return cv::Mat(); });
  EXPECT_LT(std::chrono::steady_clock::now() - t0, std::chrono::seconds(1))
      << "submitting waited for the stalled writer";
  release.set_value();
  writer.flush();
  // Parts 2 and 3 waited longest and were dropped; 4 and 5 were written after 1.
  EXPECT_EQ(pngsOfPart(dir.path, 1), 1);
  EXPECT_EQ(pngsOfPart(dir.path, 2), 0);
  EXPECT_EQ(pngsOfPart(dir.path, 3), 0);
  EXPECT_EQ(pngsOfPart(dir.path, 4), 1);
  EXPECT_EQ(pngsOfPart(dir.path, 5), 1);
  EXPECT_NE(metrics.exposition().find("facet_archive_dropped_total 2"), std::string::npos)
      << metrics.exposition();
}

TEST(ArchiveWriter, WritesWhatIsQueuedBeforeItStops) {
  const Folder dir;
  ImageArchive archive({.folder = dir.path});
  MetricsRegistry metrics;
  {
    ArchiveWriter writer(archive, metrics, 8);
    for (std::uint64_t id = 1; id <= 6; ++id)
      writer.submit(test::partWith(id, Verdict::Fail),
                    cv::Mat(64, 64, CV_8U, cv::Scalar(double(id))), [] { return cv::Mat(); });
  }
  for (std::uint64_t id = 1; id <= 6; ++id) EXPECT_EQ(pngsOfPart(dir.path, id), 1) << id;
}

}  // namespace
}  // namespace facet::service
