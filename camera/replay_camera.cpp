#include "camera/replay_camera.hpp"

#include <thread>

#include <spdlog/spdlog.h>

#include "camera/image_file_list.hpp"
#include "camera/image_file_reader.hpp"
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
  if (settings_.trigger == TriggerMode::Hardware)
    throw CameraError("replay camera: hardware trigger is not possible, use software");
}

void ReplayCamera::open() {
  auto files = listRecordedFiles(settings_.folder, settings_.glob, imageExtensions());
  if (files.empty())
    throw CameraError("replay folder " + settings_.folder.string() + " has no image" +
                      (settings_.glob.empty() ? "" : " matching \"" + settings_.glob + "\""));
  auto sidecar = SidecarMetadata::loadFolder(settings_.folder);
  std::lock_guard lock(mutex_);
  files_ = std::move(files);
  reported_.assign(files_.size(), false);
  sidecar_ = std::move(sidecar);
  next_file_ = 0;
  health_.connected = true;
  spdlog::info("replay: {} images in {}", files_.size(), settings_.folder.string());
}

void ReplayCamera::start() {
  std::lock_guard lock(mutex_);
  if (!health_.connected) throw CameraError("replay camera " + name() + ": start() before open()");
  health_.streaming = true;
  pending_triggers_ = 0;
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

GrabResult ReplayCamera::readNext(std::unique_lock<std::mutex>& lock) {
  // At most one pass over the folder per grab: a folder of only broken files must end.
  for (std::size_t attempts = 0; attempts < files_.size(); ++attempts) {
    if (next_file_ >= files_.size()) {
      if (!settings_.loop) return {GrabStatus::EndOfStream, {}, "replay finished"};
      next_file_ = 0;
    }
    const std::size_t index = next_file_++;
    const std::filesystem::path file = files_[index];
    // Decode without the lock: health() and softwareTrigger() must not wait for a PNG.
    lock.unlock();
    ImageFileContent content = readImageFile(file, settings_.max_pixels);
    Frame frame;
    std::string sidecar_error;
    if (content.ok()) {
      frame.image = std::move(content.image);
      frame.format = content.format;
      applyColourConversion(frame.image, frame.format, settings_.colour);
      frame.timestamp = std::chrono::system_clock::now();
      frame.source = file.string();
      frame.metadata = sidecar_.forImage(file, &sidecar_error);
    } else {
      spdlog::error("replay: skipping {}", content.error);
    }
    lock.lock();
    if (!content.ok()) {
      ++health_.skipped_files;
      health_.last_error = content.error;
      // Reported once: a looping replay must not turn one bad file into a stream of parts.
      if (!settings_.report_unreadable || reported_[index]) continue;
      reported_[index] = true;
      Frame refused;  // no image and no frame number: only where it came from
      refused.source = file.string();
      refused.metadata = sidecar_.forImage(file, &sidecar_error);
      return {GrabStatus::Error, std::move(refused), content.error};
    }
    if (!sidecar_error.empty()) health_.last_error = sidecar_error;
    frame.id = next_id_++;
    ++health_.frames;
    return {GrabStatus::Ok, std::move(frame), {}};
  }
  if (next_file_ >= files_.size() && !settings_.loop)
    return {GrabStatus::EndOfStream, {}, "replay finished"};
  return {GrabStatus::Error, {}, "no readable image in " + settings_.folder.string()};
}

void ReplayCamera::stop() {
  {
    std::lock_guard lock(mutex_);
    health_.streaming = false;
  }
  trigger_cv_.notify_all();
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
