#pragma once
// The image archive: failed parts (and a sample of good ones) saved as the raw image plus a PNG
// with overlays, under a disk quota with the oldest files removed first. A failing disk never
// stops inspection: the archive reports itself degraded and the daemon carries on.

#include <cstdint>
#include <deque>
#include <filesystem>
#include <functional>
#include <mutex>
#include <optional>
#include <string>

#include <opencv2/core.hpp>

#include "service/engine/part_result.hpp"

namespace facet::service {

struct ArchivePolicy {
  std::filesystem::path folder;           // created when missing
  std::uint64_t quotaBytes = 1ull << 30;  // total size of the archive's files, bytes (1 GiB)
  bool failed = true;                     // archive failed and error parts
  int goodEvery = 0;                      // also every N-th good part (0 = none)
};

struct ArchivedPart {
  std::filesystem::path raw;      // the image as grabbed (PNG, lossless, 8 or 16 bit)
  std::filesystem::path overlay;  // the image with overlays (8-bit colour PNG)
};

class ImageArchive {
 public:
  // Scans the folder for files written by earlier runs so the quota covers them too.
  explicit ImageArchive(ArchivePolicy policy);

  // Archives the part when the policy asks for it (wants(), then store()). Never throws: on
  // failure the archive turns degraded (see degraded()) and nothing is returned.
  std::optional<ArchivedPart> archive(const PartResult& part, const cv::Mat& raw,
                                      const cv::Mat& overlay);
  // The same, drawing the overlay picture only when the part is archived (drawing a large
  // frame costs milliseconds that good, unarchived parts need not pay).
  std::optional<ArchivedPart> archive(const PartResult& part, const cv::Mat& raw,
                                      const std::function<cv::Mat()>& drawOverlay);

  // Whether the policy keeps the part: a failed or error part, or every N-th good one (the good
  // parts it is asked about are counted for that).
  bool wants(const PartResult& part);
  // Writes the part's pictures, whatever the policy (asked before: wants()). Never throws, as
  // archive().
  std::optional<ArchivedPart> store(const PartResult& part, const cv::Mat& raw,
                                    const std::function<cv::Mat()>& drawOverlay);

  [[nodiscard]] bool degraded() const;
  [[nodiscard]] std::string lastError() const;
  [[nodiscard]] std::uint64_t bytesUsed() const;
  [[nodiscard]] std::uint64_t writeFailures() const;
  [[nodiscard]] std::uint64_t filesRemoved() const;

 private:
  // Encodes and writes without the lock, then records the file under it.
  void writeFile(const std::filesystem::path& file, const cv::Mat& image);
  void enforceQuota();  // under the lock

  ArchivePolicy policy_;
  mutable std::mutex mutex_;
  std::deque<std::pair<std::filesystem::path, std::uint64_t>> files_;  // oldest first
  std::uint64_t bytes_ = 0;
  std::uint64_t goodSeen_ = 0;
  std::uint64_t writeFailures_ = 0;
  std::uint64_t removed_ = 0;
  bool degraded_ = false;
  std::string lastError_;
};

}  // namespace facet::service
