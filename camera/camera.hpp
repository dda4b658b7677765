#pragma once
// The Camera interface: one way for the daemon to get frames, whatever the source (a replayed
// folder, a GigE Vision / USB3 Vision camera through Aravis, or a V4L2 device).

#include <chrono>
#include <cstdint>
#include <map>
#include <memory>
#include <stdexcept>
#include <string>

#include <opencv2/core/mat.hpp>

namespace facet {

// Pixel layout of Frame::image.
enum class PixelFormat {
  Mono8,   // CV_8UC1
  Mono16,  // CV_16UC1 (the full 16-bit range; 10/12-bit sensors are not rescaled)
  Bgr8,    // CV_8UC3, OpenCV channel order
};

const char* toString(PixelFormat format);

// One image as delivered by a camera.
struct Frame {
  cv::Mat image;  // Mono8, Mono16 or Bgr8 as told by `format`; owns or shares its pixels
  PixelFormat format = PixelFormat::Mono8;
  // Frame counter of this camera session, monotonically increasing. Device counters that wrap
  // (16-bit GVSP block ids, 32-bit V4L2 sequence numbers) are unwrapped into 64 bits, so a gap
  // in `id` means frames were lost.
  std::uint64_t id = 0;
  // Host time when the frame was received (replay: when it was read).
  std::chrono::system_clock::time_point timestamp{};
  // Device clock in nanoseconds when the device gives one (0 otherwise).
  std::uint64_t device_timestamp_ns = 0;
  // False when pixel data is missing (lost packets, short V4L2 buffer). Such a frame must never
  // be inspected as a good part; backends return it only with GrabStatus::Incomplete, with
  // id, timestamp and source set and `image` empty.
  bool complete = true;
  // Where the frame came from: the image file path for replay, the camera id otherwise.
  std::string source;
  // Per-frame metadata. Replay fills it from sidecar files (keys such as "serial",
  // "expected_verdict"); string values are stored as-is, other JSON values as their JSON text.
  std::map<std::string, std::string> metadata;
};

enum class GrabStatus {
  Ok,            // `frame` holds a complete image
  Timeout,       // no frame within the timeout (not an error: e.g. waiting for a trigger)
  Incomplete,    // `frame` is set but `frame.complete == false`; counted in CameraHealth
  EndOfStream,   // replay without loop has delivered every file
  Disconnected,  // the device is gone; the backend keeps trying to reconnect (see health())
  NotStarted,    // grab() called before start() or after stop()
  Error,         // anything else; `message` says what
};

const char* toString(GrabStatus status);

// The result of Camera::grab(): a frame or the typed reason why there is none.
struct GrabResult {
  GrabStatus status = GrabStatus::Error;
  Frame frame;          // valid for Ok and Incomplete (replay Error: source, see ReplaySettings)
  std::string message;  // human-readable detail for anything but Ok

  bool ok() const { return status == GrabStatus::Ok; }
  explicit operator bool() const { return ok(); }
};

// Counters and state of a camera, cheap to read from any thread (e.g. the /health endpoint).
struct CameraHealth {
  bool connected = false;    // device open (replay: folder readable)
  bool streaming = false;    // between start() and stop()
  std::uint64_t frames = 0;  // complete frames delivered
  std::uint64_t incomplete_frames = 0;
  std::uint64_t lost_frames = 0;  // gaps in the device's frame counter
  std::uint64_t timeouts = 0;
  std::uint64_t reconnects = 0;     // successful reconnections after the device was lost
  std::uint64_t skipped_files = 0;  // replay: unreadable, truncated or oversized files
  std::string last_error;           // latest error message, empty if none
};

// Thrown by open() and start() when the camera cannot be used at all (missing folder, no such
// device, unsupported pixel format). The message names the folder or device.
class CameraError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

// Life cycle: open() -> start() -> grab()* -> stop() -> close(); start/stop may repeat.
// Threads: grab() runs on one acquisition thread; softwareTrigger() may be called from another
// thread meanwhile; health() and name() from any thread. open/start/stop/close come from one
// controlling thread and never while grab() is running (grab returns within its timeout, so
// stop the acquisition loop first). Runtime trouble (timeouts, lost devices, bad files) is
// reported by grab()'s status, never thrown.
class Camera {
 public:
  virtual ~Camera() = default;

  virtual void open() = 0;
  virtual void start() = 0;
  // Waits at most `timeout` for the next frame. A frame is copied at most once between the
  // driver's buffer and the returned Frame.
  virtual GrabResult grab(std::chrono::milliseconds timeout) = 0;
  // In software trigger mode, asks for exactly one frame. Ignored in free-run mode.
  virtual void softwareTrigger() = 0;
  virtual void stop() = 0;
  virtual void close() = 0;

  virtual CameraHealth health() const = 0;
  // Human-readable identity: "replay:/data/run1", "aravis:Fake-GV01", "v4l2:/dev/video0".
  virtual std::string name() const = 0;
};

}  // namespace facet
