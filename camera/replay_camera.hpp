#pragma once
// ReplayCamera: a folder of recorded images played back as if a camera were taking them.
//
// Decoding a recorded PNG takes longer than a real camera needs to deliver a frame, so by
// default the next files are read ahead on a background thread (ReplaySettings::prefetch) and
// grab() hands out a frame already in memory. What grab() reports is unchanged by the read-ahead:
// files are delivered in the same order, a bad file is counted, logged and skipped when grab()
// reaches it (not when it was read), and frame ids and timestamps are given at delivery.

#include <chrono>
#include <condition_variable>
#include <deque>
#include <filesystem>
#include <mutex>
#include <thread>
#include <vector>

#include "camera/camera.hpp"
#include "camera/camera_settings.hpp"
#include "camera/image_file_reader.hpp"
#include "camera/sidecar_metadata.hpp"

namespace facet {

class ReplayCamera final : public Camera {
 public:
  explicit ReplayCamera(ReplaySettings settings);
  ~ReplayCamera() override;  // stops the read-ahead thread
  ReplayCamera(const ReplayCamera&) = delete;
  ReplayCamera& operator=(const ReplayCamera&) = delete;

  // Lists the folder and reads its sidecar.json; throws CameraError when the folder is
  // missing, holds no matching image, or its sidecar.json is malformed.
  void open() override;
  void start() override;
  // Free run: the next readable file (paced to `fps` if set). Software trigger: the next
  // readable file once a trigger is pending. Unreadable files are skipped, logged and counted.
  // With read-ahead, waits for the file being read if it is not ready yet (as without).
  GrabResult grab(std::chrono::milliseconds timeout) override;
  void softwareTrigger() override;
  void stop() override;
  void close() override;
  CameraHealth health() const override;
  std::string name() const override;

  // The files this replay will play, in order (after open()).
  std::vector<std::filesystem::path> files() const;

 private:
  // One file as read (ahead or inside grab()), not yet delivered.
  struct ReadFile {
    std::size_t index = 0;      // into files_
    bool end_of_files = false;  // no file left (replay without loop)
    ImageFileContent content;
    SidecarMetadata::Entries metadata;
    std::string sidecar_error;
  };
  ReadFile readFile(std::size_t index, const std::filesystem::path& file) const;
  // The next file to deliver: taken from the read-ahead queue, or read here without read-ahead.
  // Returns false when the camera was stopped while waiting.
  bool nextRead(std::unique_lock<std::mutex>& lock, ReadFile& out);
  GrabResult readNext(std::unique_lock<std::mutex>& lock);
  void readAheadLoop();
  void stopReadAhead(std::unique_lock<std::mutex>& lock);

  ReplaySettings settings_;
  mutable std::mutex mutex_;
  std::condition_variable trigger_cv_;
  std::vector<std::filesystem::path> files_;
  SidecarMetadata sidecar_;
  std::size_t next_file_ = 0;  // the file after the last one delivered (or skipped)
  // Read-ahead (settings_.prefetch > 0): files from next_file_ on, read by read_ahead_.
  std::thread read_ahead_;
  bool read_ahead_running_ = false;
  std::deque<ReadFile> ready_;        // read, in delivery order; at most settings_.prefetch
  std::size_t next_to_read_ = 0;      // the file the read-ahead thread reads next
  bool end_queued_ = false;           // ready_ ends with the end-of-files mark
  std::condition_variable ready_cv_;  // a file was read, or the camera stopped
  std::condition_variable space_cv_;  // room in ready_, or the camera stopped
  std::vector<bool> reported_;        // report_unreadable: files already returned as an Error
  std::uint64_t next_id_ = 0;
  std::uint64_t pending_triggers_ = 0;
  std::chrono::steady_clock::time_point next_due_{};
  CameraHealth health_;
};

}  // namespace facet
