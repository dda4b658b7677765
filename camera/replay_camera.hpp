#pragma once
// ReplayCamera: a folder of recorded images played back as if a camera were taking them.

#include <chrono>
#include <condition_variable>
#include <filesystem>
#include <mutex>
#include <vector>

#include "camera/camera.hpp"
#include "camera/camera_settings.hpp"
#include "camera/sidecar_metadata.hpp"

namespace facet {

class ReplayCamera final : public Camera {
 public:
  explicit ReplayCamera(ReplaySettings settings);

  // Lists the folder and reads its sidecar.json; throws CameraError when the folder is
  // missing, holds no matching image, or its sidecar.json is malformed.
  void open() override;
  void start() override;
  // Free run: the next readable file (paced to `fps` if set). Software trigger: the next
  // readable file once a trigger is pending. Unreadable files are skipped, logged and counted.
  GrabResult grab(std::chrono::milliseconds timeout) override;
  void softwareTrigger() override;
  void stop() override;
  void close() override;
  CameraHealth health() const override;
  std::string name() const override;

  // The files this replay will play, in order (after open()).
  std::vector<std::filesystem::path> files() const;

 private:
  GrabResult readNext(std::unique_lock<std::mutex>& lock);

  ReplaySettings settings_;
  mutable std::mutex mutex_;
  std::condition_variable trigger_cv_;
  std::vector<std::filesystem::path> files_;
  SidecarMetadata sidecar_;
  std::size_t next_file_ = 0;
  std::vector<bool> reported_;  // report_unreadable: files already returned as an Error
  std::uint64_t next_id_ = 0;
  std::uint64_t pending_triggers_ = 0;
  std::chrono::steady_clock::time_point next_due_{};
  CameraHealth health_;
};

}  // namespace facet
