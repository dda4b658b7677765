#pragma once
// V4l2Camera: a USB (UVC) camera through Video4Linux2, mmap streaming.
//
// - Format negotiation: the requested FourCC (GREY, YUYV or MJPG) or, without one, the first of
//   GREY, YUYV, MJPG that the device offers; the size the driver settles on is used.
// - Exposure and gain are set where the device has those controls (a missing control is
//   logged, not an error).
// - Each frame is converted straight out of the mmap buffer (YUYV -> BGR/grey, MJPG decoded),
//   which is the one copy; the buffer is queued again at once.
// - A device that disappears (ENODEV, POLLERR) is reported as Disconnected and reopened with
//   exponential backoff on later grab() calls.

#include <chrono>
#include <cstdint>
#include <memory>
#include <mutex>
#include <string>
#include <vector>

#include "camera/camera.hpp"
#include "camera/camera_settings.hpp"
#include "camera/frame_id_unwrapper.hpp"
#include "camera/v4l2_syscalls.hpp"

namespace facet {

class V4l2Camera final : public Camera {
 public:
  explicit V4l2Camera(V4l2Settings settings,
                      std::shared_ptr<V4l2Syscalls> syscalls = kernelV4l2Syscalls());
  ~V4l2Camera() override;
  V4l2Camera(const V4l2Camera&) = delete;
  V4l2Camera& operator=(const V4l2Camera&) = delete;

  void open() override;
  void start() override;
  GrabResult grab(std::chrono::milliseconds timeout) override;
  void softwareTrigger() override {}  // UVC cameras free-run
  void stop() override;
  void close() override;
  CameraHealth health() const override;
  std::string name() const override;

  // The negotiated format (after open()): FourCC as text, width, height.
  std::string fourcc() const;
  int width() const { return width_; }
  int height() const { return height_; }

 private:
  struct MappedBuffer {
    void* data = nullptr;
    std::size_t length = 0;
  };

  void openDevice();  // throws CameraError
  void negotiateFormat();
  void applyControls();
  void startStreaming();  // throws CameraError
  void releaseDevice();
  void markLost(const std::string& why);
  GrabResult tryReconnect(std::chrono::steady_clock::time_point deadline);
  [[noreturn]] void fail(const std::string& what) const;

  V4l2Settings settings_;
  std::shared_ptr<V4l2Syscalls> sys_;
  int fd_ = -1;
  std::uint32_t pixel_format_ = 0;
  int width_ = 0;
  int height_ = 0;
  int bytes_per_line_ = 0;
  std::vector<MappedBuffer> buffers_;
  bool streaming_ = false;
  bool lost_ = false;
  std::chrono::steady_clock::time_point next_attempt_{};
  std::chrono::milliseconds backoff_{0};
  FrameIdUnwrapper ids_{32, false};

  mutable std::mutex health_mutex_;
  CameraHealth health_;
};

}  // namespace facet
