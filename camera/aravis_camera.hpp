#pragma once
// AravisCamera: a GigE Vision / USB3 Vision camera through Aravis 0.8. It lives in the GigE Vision
// camera module; facet and facetd make it through makeCamera (aravis_backend.hpp), never link it.
//
// - Opened by address (GigE, no discovery needed), serial number, Aravis device id, or the
//   first camera found, in that order of preference.
// - The stream uses Aravis' automatic socket buffer, sized to a frame before acquisition starts
//   (Aravis waits for the first packet). The packet-socket fast path is turned off
//   for cameras on a loopback address (it cannot capture there, e.g. the fake camera as root).
// - A frame with missing packets is returned as GrabStatus::Incomplete without pixels and is
//   counted; it is never handed out as a good frame.
// - While streaming, a watch thread asks the control channel whether the camera is still there
//   (and still ours) once no frame has come for a second, whatever the trigger mode: a triggered
//   camera waiting for its next part is silent too, and Aravis' own heartbeat never reports a
//   camera that stopped answering. A software trigger left unanswered counts as the same
//   evidence. A lost camera shows in health() at once (connected = false);
//   grab() reports Disconnected while a background thread releases the dead device (Aravis
//   blocks for seconds on it) and reconnects with exponential backoff. When no grab() runs
//   (e.g. waiting for a PLC trigger), the watch thread does the same, so health() also shows the
//   return without a part being spent on it.

#include <atomic>
#include <chrono>
#include <condition_variable>
#include <mutex>
#include <string>
#include <thread>

#include "camera/camera.hpp"
#include "camera/camera_settings.hpp"
#include "camera/frame_id_unwrapper.hpp"

typedef struct _ArvCamera ArvCamera;
typedef struct _ArvStream ArvStream;

namespace facet {

class AravisCamera final : public Camera {
 public:
  explicit AravisCamera(AravisSettings settings);
  ~AravisCamera() override;
  AravisCamera(const AravisCamera&) = delete;
  AravisCamera& operator=(const AravisCamera&) = delete;

  // Finds and configures the camera; throws CameraError naming it when it cannot be found or a
  // setting is refused.
  void open() override;
  void start() override;
  GrabResult grab(std::chrono::milliseconds timeout) override;
  void softwareTrigger() override;
  void stop() override;
  void close() override;
  CameraHealth health() const override;
  std::string name() const override;

 private:
  void connect();  // open + configure; throws CameraError
  void startStream();
  void releaseDevice(bool device_alive);
  void flagLost(const std::string& why);
  void markLost();
  void reconnectLoop(ArvCamera* dead_camera, ArvStream* dead_stream);
  void stopReconnecting();
  void finishReconnect();
  GrabResult waitForReconnect(std::chrono::steady_clock::time_point deadline);
  std::string controlChannelProblem();  // empty while the camera answers and is ours
  void startWatching();
  void stopWatching();
  void watch();
  void noteSignOfLife();
  static void onControlLost(void* device, void* self);

  AravisSettings settings_;
  std::string label_;  // what we were asked to open, for messages

  mutable std::mutex device_mutex_;  // guards camera_/stream_ against softwareTrigger()
  ArvCamera* camera_ = nullptr;
  ArvStream* stream_ = nullptr;
  std::string device_id_;
  bool streaming_ = false;
  std::atomic<bool> lost_{false};
  std::atomic<bool> control_lost_{false};  // seen lost, not yet handled by markLost()
  std::string loss_reason_;                // guarded by health_mutex_

  // grab(), and the watch thread when it handles a loss or a return, hold `grab_mutex_`: only
  // one of them swaps the device and stream at a time.
  std::mutex grab_mutex_;
  std::thread watch_thread_;
  std::mutex watch_mutex_;
  std::condition_variable watch_cv_;
  bool stop_watching_ = false;  // guarded by watch_mutex_
  // Last frame or answer on the control channel, in steady_clock ticks.
  std::atomic<std::chrono::steady_clock::rep> last_sign_of_life_{0};

  // Reconnection runs on its own thread; grab() waits on `reconnect_cv_` for it.
  std::thread reconnect_thread_;
  std::condition_variable reconnect_cv_;
  bool reconnected_ = false;        // guarded by device_mutex_
  bool stop_reconnecting_ = false;  // guarded by device_mutex_
  FrameIdUnwrapper ids_{16, true};
  bool extended_ids_ = false;

  mutable std::mutex health_mutex_;
  CameraHealth health_;
};

}  // namespace facet
