#include "service/daemon/image_archive.hpp"

#include <algorithm>
#include <fstream>
#include <stdexcept>
#include <vector>

#include <opencv2/imgcodecs.hpp>

namespace facet::service {

namespace fs = std::filesystem;

ImageArchive::ImageArchive(ArchivePolicy policy) : policy_(std::move(policy)) {
  std::error_code ec;
  fs::create_directories(policy_.folder, ec);
  if (ec) {
    degraded_ = true;
    lastError_ = policy_.folder.string() + ": " + ec.message();
    return;
  }
  std::vector<std::pair<fs::file_time_type, std::pair<fs::path, std::uint64_t>>> found;
  for (const auto& entry : fs::recursive_directory_iterator(policy_.folder, ec)) {
    if (!entry.is_regular_file() || entry.path().extension() != ".png") continue;
    found.push_back({entry.last_write_time(), {entry.path(), entry.file_size()}});
  }
  std::sort(found.begin(), found.end());
  for (auto& [time, file] : found) {
    bytes_ += file.second;
    files_.push_back(std::move(file));
  }
}

bool ImageArchive::wanted(const PartResult& part) {
  if (part.verdict != Verdict::Pass) return policy_.failed;
  ++goodSeen_;
  return policy_.goodEvery > 0 && goodSeen_ % static_cast<std::uint64_t>(policy_.goodEvery) == 0;
}

void ImageArchive::writeFile(const fs::path& file, const cv::Mat& image) {
  std::vector<unsigned char> png;
  if (!cv::imencode(".png", image, png))
    throw std::runtime_error(file.string() + ": cannot encode");
  // Written to a temporary name and renamed, so a full disk never leaves a truncated PNG behind.
  const fs::path partial = file.string() + ".partial";
  {
    std::ofstream out(partial, std::ios::binary);
    out.write(reinterpret_cast<const char*>(png.data()), static_cast<std::streamsize>(png.size()));
    out.flush();
    if (!out) {
      std::error_code ignore;
      fs::remove(partial, ignore);
      throw std::runtime_error(file.string() + ": write failed (disk full?)");
    }
  }
  fs::rename(partial, file);
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
  std::lock_guard lock(mutex_);
  if (!wanted(part) || raw.empty()) return std::nullopt;
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
    enforceQuota();
    degraded_ = false;
    return out;
  } catch (const std::exception& e) {
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
