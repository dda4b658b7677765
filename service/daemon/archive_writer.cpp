#include "service/daemon/archive_writer.hpp"

#include <spdlog/spdlog.h>

namespace facet::service {

ArchiveWriter::ArchiveWriter(ImageArchive& archive, MetricsRegistry& metrics, std::size_t capacity)
    : archive_(archive),
      metrics_(metrics),
      queue_(capacity, OverflowPolicy::DropOldest),
      thread_([this] { run(); }) {
  droppedParts();  // exported from the start, at 0
}

Counter& ArchiveWriter::droppedParts() {
  return metrics_.counter("facet_archive_dropped_total",
                          "Parts whose pictures the archive had no time for");
}

ArchiveWriter::~ArchiveWriter() {
  queue_.close();  // the thread drains what is queued, then ends
  if (thread_.joinable()) thread_.join();
}

void ArchiveWriter::submit(const PartResult& part, cv::Mat frame,
                           std::function<cv::Mat()> drawOverlay) {
  if (frame.empty() || !archive_.wants(part)) return;
  {
    std::lock_guard lock(doneMutex_);
    ++submitted_;
  }
  std::optional<Job> dropped = queue_.push({part, std::move(frame), std::move(drawOverlay)});
  if (!dropped) return;
  droppedParts().increment();
  spdlog::warn("archive: part {} not archived: the archive is {} parts behind",
               dropped->part.partId, queue_.size());
  std::lock_guard lock(doneMutex_);
  ++done_;
  doneCv_.notify_all();
}

void ArchiveWriter::flush() {
  std::unique_lock lock(doneMutex_);
  doneCv_.wait(lock, [&] { return done_ >= submitted_; });
}

void ArchiveWriter::run() {
  while (true) {
    std::optional<Job> job = queue_.pop(std::chrono::milliseconds(100));
    if (!job) {
      if (queue_.closed() && queue_.size() == 0) return;
      continue;
    }
    archive_.store(job->part, job->frame, job->drawOverlay);
    std::lock_guard lock(doneMutex_);
    ++done_;
    doneCv_.notify_all();
  }
}

}  // namespace facet::service
