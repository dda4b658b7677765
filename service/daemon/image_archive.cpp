#include "service/daemon/image_archive.hpp"

#include <fcntl.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cstring>
#include <stdexcept>
#include <vector>

#include "camera/image_codecs.hpp"

namespace facet::service {

namespace fs = std::filesystem;

namespace {

constexpr std::string_view kPartialSuffix = ".partial";

std::runtime_error writeError(const fs::path& file, int error) {
  return std::runtime_error(file.string() + ": " + std::strerror(error) +
                            (error == ENOSPC || error == EDQUOT ? " (archive disk full)" : ""));
}

// Writes every byte or throws with errno's reason; a write(2) may store only part of the buffer
// (a filling disk), so loop until it is all written or the disk refuses more.
void writeAll(const fs::path& file, const std::vector<unsigned char>& bytes) {
  const int fd = ::open(file.c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0644);
  if (fd < 0) throw writeError(file, errno);
  std::size_t done = 0;
  while (done < bytes.size()) {
    const ssize_t n = ::write(fd, bytes.data() + done, bytes.size() - done);
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0) {
      const int error = n < 0 ? errno : ENOSPC;
      ::close(fd);
      throw writeError(file, error);
    }
    done += static_cast<std::size_t>(n);
  }
  // Some filesystems (NFS, quotas) report a full disk only when the file is closed.
  if (::close(fd) != 0) throw writeError(file, errno);
}

}  // namespace

ImageArchive::ImageArchive(ArchivePolicy policy) : policy_(std::move(policy)) {
  std::error_code ec;
  fs::create_directories(policy_.folder, ec);
  if (ec) {
    degraded_ = true;
    lastError_ = policy_.folder.string() + ": " + ec.message();
    return;
  }
  std::vector<std::pair<fs::file_time_type, std::pair<fs::path, std::uint64_t>>> found;
  std::vector<fs::path> stale;
  for (const auto& entry : fs::recursive_directory_iterator(policy_.folder, ec)) {
    if (entry.is_regular_file() && entry.path().extension() == kPartialSuffix)
      stale.push_back(entry.path());  // a write cut short by a crash or power loss
    if (!entry.is_regular_file() || entry.path().extension() != ".png") continue;
    found.push_back({entry.last_write_time(), {entry.path(), entry.file_size()}});
  }
  for (const auto& file : stale) fs::remove(file, ec);
  std::sort(found.begin(), found.end());
  for (auto& [time, file] : found) {
    bytes_ += file.second;
    files_.push_back(std::move(file));
  }
}

bool ImageArchive::wants(const PartResult& part) {
  std::lock_guard lock(mutex_);
  if (part.verdict != Verdict::Pass) return policy_.failed;
  ++goodSeen_;
  return policy_.goodEvery > 0 && goodSeen_ % static_cast<std::uint64_t>(policy_.goodEvery) == 0;
}

void ImageArchive::writeFile(const fs::path& file, const cv::Mat& image) {
  std::vector<unsigned char> png;
  if (!encodeImage(".png", image, png)) throw std::runtime_error(file.string() + ": cannot encode");
  // Written to a temporary name and renamed, so a full disk never leaves a truncated PNG behind.
  const fs::path partial = file.string() + std::string(kPartialSuffix);
  try {
    writeAll(partial, png);
    fs::rename(partial, file);
  } catch (...) {
    std::error_code ignore;
    fs::remove(partial, ignore);
    throw;
  }
  std::lock_guard lock(mutex_);
  files_.push_back({file, png.size()});
  bytes_ += png.size();
}

void ImageArchive::enforceQuota() {
  while (bytes_ > policy_.quotaBytes && !files_.empty()) {
    auto [file, size] = files_.front();
    files_.pop_front();
    std::error_code ec;
    fs::remove(file, ec);
    bytes_ -= std::min(bytes_, size);
    ++removed_;
  }
}

std::optional<ArchivedPart> ImageArchive::archive(const PartResult& part, const cv::Mat& raw,
                                                  const cv::Mat& overlay) {
  return archive(part, raw, [&overlay] { return overlay; });
}

std::optional<ArchivedPart> ImageArchive::archive(const PartResult& part, const cv::Mat& raw,
                                                  const std::function<cv::Mat()>& drawOverlay) {
  if (!wants(part)) return std::nullopt;
  return store(part, raw, drawOverlay);
}

std::optional<ArchivedPart> ImageArchive::store(const PartResult& part, const cv::Mat& raw,
                                                const std::function<cv::Mat()>& drawOverlay) {
  if (raw.empty()) return std::nullopt;
  // The lock is taken for the bookkeeping only (writeFile, below): encoding and writing take tens
  // of milliseconds, and wants() and the health readers must not wait for them.
  try {
    const std::time_t secs = std::chrono::system_clock::to_time_t(part.time);
    std::tm tm{};
    gmtime_r(&secs, &tm);
    char day[16];
    std::strftime(day, sizeof day, "%Y%m%d", &tm);
    const fs::path dir = policy_.folder / day;
    fs::create_directories(dir);
    const std::string stem =
        "part-" + std::to_string(part.partId) + "-" + verdictName(part.verdict);
    ArchivedPart out{dir / (stem + ".png"), dir / (stem + "-overlay.png")};
    writeFile(out.raw, raw);
    if (const cv::Mat overlay = drawOverlay(); !overlay.empty()) writeFile(out.overlay, overlay);
    std::lock_guard lock(mutex_);
    enforceQuota();
    degraded_ = false;
    return out;
  } catch (const std::exception& e) {
    std::lock_guard lock(mutex_);
    ++writeFailures_;
    degraded_ = true;
    lastError_ = e.what();
    enforceQuota();
    return std::nullopt;
  }
}

bool ImageArchive::degraded() const {
  std::lock_guard lock(mutex_);
  return degraded_;
}
std::string ImageArchive::lastError() const {
  std::lock_guard lock(mutex_);
  return lastError_;
}
std::uint64_t ImageArchive::bytesUsed() const {
  std::lock_guard lock(mutex_);
  return bytes_;
}
std::uint64_t ImageArchive::writeFailures() const {
  std::lock_guard lock(mutex_);
  return writeFailures_;
}
std::uint64_t ImageArchive::filesRemoved() const {
  std::lock_guard lock(mutex_);
  return removed_;
}

}  // namespace facet::service
