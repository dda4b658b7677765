#include "camera/replay_camera.hpp"

#include <thread>

#include <spdlog/spdlog.h>

#include "camera/image_file_list.hpp"
#include "camera/sensor_image.hpp"

namespace facet {
namespace {

const std::vector<std::string>& imageExtensions() {
  static const std::vector<std::string> extensions = {".png", ".tif", ".tiff", ".bmp", ".pgm",
                                                      ".ppm", ".pnm", ".pbm",  ".jpg", ".jpeg"};
  return extensions;
}

}  // namespace

ReplayCamera::ReplayCamera(ReplaySettings settings) : settings_(std::move(settings)) {
  if (settings_.folder.empty()) throw CameraError("replay camera: no folder given");
  if (settings_.fps < 0.0) throw CameraError("replay camera: fps must be >= 0");
  if (settings_.prefetch < 0) throw CameraError("replay camera: prefetch must be >= 0");
  if (settings_.trigger == TriggerMode::Hardware)
    throw CameraError("replay camera: hardware trigger is not possible, use software");
}

ReplayCamera::~ReplayCamera() {
  stop();
}

void ReplayCamera::open() {
  auto files = listRecordedFiles(settings_.folder, settings_.glob, imageExtensions());
  if (files.empty())
    throw CameraError("replay folder " + settings_.folder.string() + " has no image" +
                      (settings_.glob.empty() ? "" : " matching \"" + settings_.glob + "\""));
  auto sidecar = SidecarMetadata::loadFolder(settings_.folder);
  std::lock_guard lock(mutex_);
  files_ = std::move(files);
  sidecar_ = std::move(sidecar);
  next_file_ = 0;
  reported_.assign(files_.size(), false);
  health_.connected = true;
  spdlog::info("replay: {} images in {}", files_.size(), settings_.folder.string());
}

void ReplayCamera::start() {
  std::lock_guard lock(mutex_);
  if (!health_.connected) throw CameraError("replay camera " + name() + ": start() before open()");
  health_.streaming = true;
  pending_triggers_ = 0;
  if (settings_.prefetch > 0 && !read_ahead_.joinable()) {
    // Reading resumes at the first file not delivered yet (a restart loses no frame).
    ready_.clear();
    end_queued_ = false;
    next_to_read_ = next_file_;
    read_ahead_running_ = true;
    read_ahead_ = std::thread([this] { readAheadLoop(); });
  }
  // The first frame is due now, once start() is done (starting a thread may take a while).
  next_due_ = std::chrono::steady_clock::now();
}

void ReplayCamera::softwareTrigger() {
  {
    std::lock_guard lock(mutex_);
    if (settings_.trigger != TriggerMode::Software || !health_.streaming) return;
    ++pending_triggers_;
  }
  trigger_cv_.notify_all();
}

GrabResult ReplayCamera::grab(std::chrono::milliseconds timeout) {
  const auto deadline = std::chrono::steady_clock::now() + timeout;
  std::unique_lock lock(mutex_);
  if (!health_.streaming) return {GrabStatus::NotStarted, {}, name() + ": not started"};

  if (settings_.trigger == TriggerMode::Software) {
    if (!trigger_cv_.wait_until(lock, deadline,
                                [&] { return pending_triggers_ > 0 || !health_.streaming; })) {
      ++health_.timeouts;
      return {GrabStatus::Timeout, {}, "no software trigger"};
    }
    if (!health_.streaming) return {GrabStatus::NotStarted, {}, name() + ": stopped"};
    --pending_triggers_;
    // The frame rate is the camera's limit in either mode: triggers faster than `fps` (a station
    // that triggers itself without a PLC took ~100 parts a second at fps 5) wait for it.
    if (settings_.fps > 0.0) {
      const auto due = next_due_;
      lock.unlock();
      std::this_thread::sleep_until(due);
      lock.lock();
      const auto period = std::chrono::duration_cast<std::chrono::steady_clock::duration>(
          std::chrono::duration<double>(1.0 / settings_.fps));
      next_due_ = std::max(due + period, std::chrono::steady_clock::now() - period);
    }
  } else if (settings_.fps > 0.0) {
    if (next_due_ > deadline) {
      lock.unlock();
      std::this_thread::sleep_until(deadline);
      lock.lock();
      ++health_.timeouts;
      return {GrabStatus::Timeout, {}, "next replay frame not due yet"};
    }
    const auto due = next_due_;
    lock.unlock();
    std::this_thread::sleep_until(due);
    lock.lock();
    // Pace from the due time, not from now, so the average rate holds; but do not try to
    // catch up after a long pause.
    const auto period = std::chrono::duration_cast<std::chrono::steady_clock::duration>(
        std::chrono::duration<double>(1.0 / settings_.fps));
    next_due_ = std::max(due + period, std::chrono::steady_clock::now() - period);
  }
  return readNext(lock);
}

ReplayCamera::ReadFile ReplayCamera::readFile(std::size_t index,
                                              const std::filesystem::path& file) const {
  ReadFile read;
  read.index = index;
  read.content = readImageFile(file, settings_.max_pixels);
  if (read.content.ok()) {
    applyColourConversion(read.content.image, read.content.format, settings_.colour);
    read.metadata = sidecar_.forImage(file, &read.sidecar_error);
  }
  return read;
}

bool ReplayCamera::nextRead(std::unique_lock<std::mutex>& lock, ReadFile& out) {
  if (settings_.prefetch == 0) {
    if (next_file_ >= files_.size()) {
      if (!settings_.loop) {
        out.end_of_files = true;
        return true;
      }
      next_file_ = 0;
    }
    const std::size_t index = next_file_++;
    const std::filesystem::path file = files_[index];
    // Decode without the lock: health() and softwareTrigger() must not wait for a PNG.
    lock.unlock();
    out = readFile(index, file);
    lock.lock();
    return true;
  }
  ready_cv_.wait(lock, [&] { return !ready_.empty() || !health_.streaming; });
  if (!health_.streaming) return false;
  if (ready_.front().end_of_files) {
    out.end_of_files = true;  // stays queued: every later grab ends the same way
    return true;
  }
  out = std::move(ready_.front());
  ready_.pop_front();
  next_file_ = out.index + 1;
  space_cv_.notify_all();
  return true;
}

GrabResult ReplayCamera::readNext(std::unique_lock<std::mutex>& lock) {
  // At most one pass over the folder per grab: a folder of only broken files must end.
  for (std::size_t attempts = 0; attempts < files_.size(); ++attempts) {
    ReadFile read;
    if (!nextRead(lock, read)) return {GrabStatus::NotStarted, {}, name() + ": stopped"};
    if (read.end_of_files) return {GrabStatus::EndOfStream, {}, "replay finished"};
    if (!read.content.ok()) {
      spdlog::error("replay: skipping {}", read.content.error);
      ++health_.skipped_files;
      health_.last_error = read.content.error;
      // Reported once: a looping replay must not turn one bad file into a stream of parts.
      if (!settings_.report_unreadable || reported_[read.index]) continue;
      reported_[read.index] = true;
      Frame refused;  // no image and no frame number: only where it came from
      refused.source = files_[read.index].string();
      refused.metadata = sidecar_.forImage(files_[read.index]);  // a bad sidecar is logged there
      return {GrabStatus::Error, std::move(refused), read.content.error};
    }
    if (!read.sidecar_error.empty()) health_.last_error = read.sidecar_error;
    Frame frame;
    frame.image = std::move(read.content.image);
    frame.format = read.content.format;
    frame.timestamp = std::chrono::system_clock::now();
    frame.source = files_[read.index].string();
    frame.metadata = std::move(read.metadata);
    frame.id = next_id_++;
    ++health_.frames;
    return {GrabStatus::Ok, std::move(frame), {}};
  }
  if (next_file_ >= files_.size() && !settings_.loop)
    return {GrabStatus::EndOfStream, {}, "replay finished"};
  return {GrabStatus::Error, {}, "no readable image in " + settings_.folder.string()};
}

void ReplayCamera::readAheadLoop() {
  std::unique_lock lock(mutex_);
  while (true) {
    space_cv_.wait(lock, [&] {
      return !read_ahead_running_ ||
             (ready_.size() < static_cast<std::size_t>(settings_.prefetch) && !end_queued_);
    });
    if (!read_ahead_running_) return;
    if (next_to_read_ >= files_.size()) {
      if (!settings_.loop) {
        ReadFile end;
        end.end_of_files = true;
        ready_.push_back(std::move(end));
        end_queued_ = true;
        ready_cv_.notify_all();
        continue;
      }
      next_to_read_ = 0;
    }
    const std::size_t index = next_to_read_++;
    const std::filesystem::path file = files_[index];
    lock.unlock();
    ReadFile read = readFile(index, file);
    lock.lock();
    if (!read_ahead_running_) return;
    ready_.push_back(std::move(read));
    ready_cv_.notify_all();
  }
}

void ReplayCamera::stopReadAhead(std::unique_lock<std::mutex>& lock) {
  if (!read_ahead_.joinable()) return;
  read_ahead_running_ = false;
  space_cv_.notify_all();
  ready_cv_.notify_all();
  std::thread reader = std::move(read_ahead_);
  lock.unlock();
  reader.join();
  lock.lock();
  // Files read but not delivered are read again after a restart (start() resumes there).
  ready_.clear();
  end_queued_ = false;
}

void ReplayCamera::stop() {
  {
    std::unique_lock lock(mutex_);
    health_.streaming = false;
    stopReadAhead(lock);
  }
  trigger_cv_.notify_all();
  ready_cv_.notify_all();
}

void ReplayCamera::close() {
  stop();
  std::lock_guard lock(mutex_);
  health_.connected = false;
}

CameraHealth ReplayCamera::health() const {
  std::lock_guard lock(mutex_);
  return health_;
}

std::string ReplayCamera::name() const {
  return "replay:" + settings_.folder.string();
}

std::vector<std::filesystem::path> ReplayCamera::files() const {
  std::lock_guard lock(mutex_);
  return files_;
}

}  // namespace facet
