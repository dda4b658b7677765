#pragma once
// ArchiveWriter: the image archive's writes on a thread of their own.
//
// A part the archive keeps (image_archive.hpp) costs two PNGs, its frame and its overlay, and
// their writes: 75 ms for a 1280x1024 frame here. On the publishing thread the PLC results of the
// parts behind it waited that long, and on a slow or full disk longer. Here the publishing thread
// only queues the part; the results store has every part whatever becomes of its pictures. The
// queue holds a few parts: when a burst of failures outruns the disk, the oldest waiting part's
// pictures are dropped, counted (facet_archive_dropped_total) and logged.

#include <condition_variable>
#include <cstddef>
#include <functional>
#include <mutex>
#include <thread>

#include <opencv2/core.hpp>

#include "service/daemon/bounded_queue.hpp"
#include "service/daemon/image_archive.hpp"
#include "service/daemon/metrics.hpp"
#include "service/engine/part_result.hpp"

namespace facet::service {

class ArchiveWriter {
 public:
  // Writes into `archive`, which must outlive the writer.
  ArchiveWriter(ImageArchive& archive, MetricsRegistry& metrics, std::size_t capacity);
  ~ArchiveWriter();  // writes what is queued, then stops
  ArchiveWriter(const ArchiveWriter&) = delete;
  ArchiveWriter& operator=(const ArchiveWriter&) = delete;

  // Queues the part's frame when the archive's policy keeps the part; never waits for the disk.
  // `drawOverlay` is called on the writer's thread.
  void submit(const PartResult& part, cv::Mat frame, std::function<cv::Mat()> drawOverlay);
  // Waits until every part submitted so far is written or dropped.
  void flush();

 private:
  struct Job {
    PartResult part;
    cv::Mat frame;
    std::function<cv::Mat()> drawOverlay;
  };
  void run();
  Counter& droppedParts();  // facet_archive_dropped_total

  ImageArchive& archive_;
  MetricsRegistry& metrics_;
  BoundedQueue<Job> queue_;
  std::mutex doneMutex_;
  std::condition_variable doneCv_;
  std::size_t submitted_ = 0, done_ = 0;  // under doneMutex_
  std::thread thread_;
};

}  // namespace facet::service
