// AravisCamera's watch on a silent camera and its reconnection: a thread asks the control channel
// whether the camera is still there when frames stop, and reconnects in the background while
// grab() reports the camera lost.
#include <arv.h>
#include <spdlog/spdlog.h>

#include <thread>

#include "camera/aravis_camera.hpp"
#include "camera/glib_error.hpp"

namespace facet {
namespace {

using Clock = std::chrono::steady_clock;

// How long a stream may stay silent before we ask the control channel whether the camera is
// still there, and how often the watch thread looks.
constexpr auto kSilenceBeforeProbe = std::chrono::milliseconds(1000);
constexpr auto kWatchPeriod = std::chrono::milliseconds(250);

// GigE Vision bootstrap register: control channel privilege (CCP), and its bits that say an
// application holds control (exclusive or shared). A camera that restarted reads 0 here.
constexpr guint32 kControlChannelPrivilege = 0x0A00;
constexpr guint32 kControlBits = 0x3;

}  // namespace

std::string AravisCamera::controlChannelProblem() {
  // A register read through GVCP; Aravis retries internally, so a failure means the camera does
  // not answer at all. A camera that answers but no longer counts us as its controller was
  // restarted (or taken over): our stream settings are gone with it.
  std::lock_guard lock(device_mutex_);
  if (!camera_) return "no device";
  if (control_lost_) return {};  // found out (e.g. by a trigger) while we waited for the lock
  ErrorSlot error;
  guint32 value = 0;
  arv_device_read_register(arv_camera_get_device(camera_), kControlChannelPrivilege, &value,
                           &error);
  if (error) return "no answer on control channel";
  if ((value & kControlBits) == 0) return "control channel privilege lost (camera restarted?)";
  return {};
}

void AravisCamera::markLost() {
  std::string why;
  {
    std::lock_guard lock(health_mutex_);
    why = loss_reason_;
    health_.connected = false;
    health_.last_error = "camera lost: " + why;
  }
  spdlog::error("aravis camera {} lost: {}; reconnecting with backoff", label_, why);
  lost_ = true;
  ArvCamera* dead_camera = nullptr;
  ArvStream* dead_stream = nullptr;
  {
    std::lock_guard lock(device_mutex_);
    if (camera_) g_signal_handlers_disconnect_by_data(arv_camera_get_device(camera_), this);
    std::swap(dead_camera, camera_);
    std::swap(dead_stream, stream_);
    reconnected_ = false;
    stop_reconnecting_ = false;
  }
  if (reconnect_thread_.joinable()) reconnect_thread_.join();
  reconnect_thread_ = std::thread(&AravisCamera::reconnectLoop, this, dead_camera, dead_stream);
}

void AravisCamera::startWatching() {
  {
    std::lock_guard lock(watch_mutex_);
    stop_watching_ = false;
  }
  watch_thread_ = std::thread([this] {
    std::unique_lock lock(watch_mutex_);
    while (!watch_cv_.wait_for(lock, kWatchPeriod, [&] { return stop_watching_; })) {
      lock.unlock();
      watch();
      lock.lock();
    }
  });
}

void AravisCamera::stopWatching() {
  {
    std::lock_guard lock(watch_mutex_);
    stop_watching_ = true;
  }
  watch_cv_.notify_all();
  if (watch_thread_.joinable()) watch_thread_.join();
}

void AravisCamera::watch() {
  if (lost_) {
    // Reconnected while no grab() waited for it: finish here, so health() tells the truth.
    bool reconnected = false;
    {
      std::lock_guard lock(device_mutex_);
      reconnected = reconnected_;
    }
    std::unique_lock grabbing(grab_mutex_, std::try_to_lock);
    if (reconnected && grabbing && lost_) finishReconnect();
    return;
  }
  const auto silence = Clock::now().time_since_epoch() - Clock::duration(last_sign_of_life_);
  if (!control_lost_ && silence > kSilenceBeforeProbe) {
    const std::string problem = controlChannelProblem();
    if (problem.empty())
      noteSignOfLife();
    else
      flagLost(problem);
  }
  if (control_lost_) {
    // A grab() in progress handles it when it returns; otherwise release and reconnect now.
    std::unique_lock grabbing(grab_mutex_, std::try_to_lock);
    if (grabbing && !lost_ && control_lost_) markLost();
  }
}

void AravisCamera::reconnectLoop(ArvCamera* dead_camera, ArvStream* dead_stream) {
  // Releasing a device that does not answer blocks in Aravis (it says goodbye with retries).
  if (dead_stream) g_object_unref(dead_stream);
  if (dead_camera) g_object_unref(dead_camera);
  auto backoff = std::chrono::milliseconds(settings_.reconnect_initial_ms);
  std::unique_lock lock(device_mutex_);
  while (!stop_reconnecting_) {
    if (reconnect_cv_.wait_for(lock, backoff, [&] { return stop_reconnecting_; })) break;
    lock.unlock();
    std::string error;
    try {
      connect();
      startStream();
    } catch (const CameraError& e) {
      error = e.what();
      releaseDevice(false);
    }
    lock.lock();
    if (error.empty()) {
      reconnected_ = true;
      reconnect_cv_.notify_all();
      return;
    }
    std::lock_guard health_lock(health_mutex_);
    health_.last_error = error;
    backoff = std::min(backoff * 2, std::chrono::milliseconds(settings_.reconnect_max_ms));
  }
}

void AravisCamera::stopReconnecting() {
  {
    std::lock_guard lock(device_mutex_);
    stop_reconnecting_ = true;
  }
  reconnect_cv_.notify_all();
  if (reconnect_thread_.joinable()) reconnect_thread_.join();
}

GrabResult AravisCamera::waitForReconnect(Clock::time_point deadline) {
  {
    std::unique_lock lock(device_mutex_);
    if (!reconnect_cv_.wait_until(lock, deadline, [&] { return reconnected_; }))
      return {GrabStatus::Disconnected, {}, "aravis camera " + label_ + " is disconnected"};
  }
  finishReconnect();
  return {GrabStatus::Ok, {}, {}};
}

void AravisCamera::finishReconnect() {
  if (reconnect_thread_.joinable()) reconnect_thread_.join();
  lost_ = false;
  reconnected_ = false;
  ids_.restart();
  spdlog::info("aravis camera {} reconnected", label_);
  std::lock_guard lock(health_mutex_);
  health_.connected = true;
  ++health_.reconnects;
}

}  // namespace facet
