#include "camera/v4l2_camera.hpp"

#include <fcntl.h>
#include <linux/videodev2.h>
#include <poll.h>
#include <sys/mman.h>

#include <algorithm>
#include <cerrno>
#include <cstring>
#include <thread>

#include <spdlog/spdlog.h>

#include "camera/fourcc.hpp"
#include "camera/image_codecs.hpp"
#include "camera/sensor_image.hpp"

namespace facet {
namespace {

using Clock = std::chrono::steady_clock;

bool deviceGone(int error) {
  return error == ENODEV || error == EIO || error == ENXIO;
}

}  // namespace

V4l2Camera::V4l2Camera(V4l2Settings settings, std::shared_ptr<V4l2Syscalls> syscalls)
    : settings_(std::move(settings)), sys_(std::move(syscalls)) {
  if (!settings_.format.empty() && settings_.format != "GREY" && settings_.format != "YUYV" &&
      settings_.format != "MJPG")
    throw CameraError("v4l2 camera " + settings_.device + ": unsupported format \"" +
                      settings_.format + "\" (use GREY, YUYV or MJPG)");
  if (settings_.buffer_count < 2)
    throw CameraError("v4l2 camera " + settings_.device + ": buffer_count must be >= 2");
  if (settings_.width < 0 || settings_.height < 0)
    throw CameraError("v4l2 camera " + settings_.device + ": negative size");
}

V4l2Camera::~V4l2Camera() {
  close();
}

void V4l2Camera::fail(const std::string& what) const {
  throw CameraError("v4l2 camera " + settings_.device + ": " + what + ": " + std::strerror(errno));
}

void V4l2Camera::openDevice() {
  fd_ = sys_->open(settings_.device, O_RDWR | O_NONBLOCK);
  if (fd_ < 0) fail("cannot open");
  v4l2_capability cap{};
  if (sys_->ioctl(fd_, VIDIOC_QUERYCAP, &cap) < 0) fail("VIDIOC_QUERYCAP");
  const std::uint32_t caps =
      (cap.capabilities & V4L2_CAP_DEVICE_CAPS) ? cap.device_caps : cap.capabilities;
  if (!(caps & V4L2_CAP_VIDEO_CAPTURE) || !(caps & V4L2_CAP_STREAMING)) {
    errno = ENOTSUP;
    fail("not a streaming video capture device");
  }
  negotiateFormat();
  applyControls();
}

void V4l2Camera::negotiateFormat() {
  std::vector<std::uint32_t> offered;
  for (std::uint32_t i = 0;; ++i) {
    v4l2_fmtdesc desc{};
    desc.index = i;
    desc.type = V4L2_BUF_TYPE_VIDEO_CAPTURE;
    if (sys_->ioctl(fd_, VIDIOC_ENUM_FMT, &desc) < 0) break;
    offered.push_back(desc.pixelformat);
  }
  auto isOffered = [&](std::uint32_t f) {
    return std::find(offered.begin(), offered.end(), f) != offered.end();
  };
  std::uint32_t wanted = 0;
  if (!settings_.format.empty()) {
    wanted = fourccOf(settings_.format);
  } else {
    for (std::uint32_t f : {V4L2_PIX_FMT_GREY, V4L2_PIX_FMT_YUYV, V4L2_PIX_FMT_MJPEG})
      if (isOffered(f)) {
        wanted = f;
        break;
      }
  }
  if (wanted == 0 || !isOffered(wanted)) {
    std::string list;
    for (auto f : offered) list += (list.empty() ? "" : ", ") + fourccText(f);
    errno = EINVAL;
    fail("format " + (settings_.format.empty() ? std::string("GREY/YUYV/MJPG") : settings_.format) +
         " not offered (device offers: " + (list.empty() ? "nothing" : list) + ")");
  }

  v4l2_format fmt{};
  fmt.type = V4L2_BUF_TYPE_VIDEO_CAPTURE;
  if (sys_->ioctl(fd_, VIDIOC_G_FMT, &fmt) < 0) fail("VIDIOC_G_FMT");
  fmt.fmt.pix.pixelformat = wanted;
  if (settings_.width > 0) fmt.fmt.pix.width = static_cast<std::uint32_t>(settings_.width);
  if (settings_.height > 0) fmt.fmt.pix.height = static_cast<std::uint32_t>(settings_.height);
  fmt.fmt.pix.field = V4L2_FIELD_NONE;
  if (sys_->ioctl(fd_, VIDIOC_S_FMT, &fmt) < 0) fail("VIDIOC_S_FMT " + fourccText(wanted));
  if (fmt.fmt.pix.pixelformat != wanted) {
    errno = EINVAL;
    fail("driver replaced " + fourccText(wanted) + " by " + fourccText(fmt.fmt.pix.pixelformat));
  }
  pixel_format_ = wanted;
  width_ = static_cast<int>(fmt.fmt.pix.width);
  height_ = static_cast<int>(fmt.fmt.pix.height);
  const int bytes_per_pixel = wanted == V4L2_PIX_FMT_YUYV ? 2 : 1;
  bytes_per_line_ = std::max(static_cast<int>(fmt.fmt.pix.bytesperline), width_ * bytes_per_pixel);
  if ((settings_.width > 0 && settings_.width != width_) ||
      (settings_.height > 0 && settings_.height != height_))
    spdlog::warn("v4l2 camera {}: asked for {}x{}, driver gives {}x{}", settings_.device,
                 settings_.width, settings_.height, width_, height_);
}

void V4l2Camera::applyControls() {
  auto hasControl = [&](std::uint32_t id) {
    v4l2_queryctrl query{};
    query.id = id;
    return sys_->ioctl(fd_, VIDIOC_QUERYCTRL, &query) == 0 &&
           !(query.flags & V4L2_CTRL_FLAG_DISABLED);
  };
  auto setControl = [&](std::uint32_t id, int value, const char* what) {
    v4l2_control control{};
    control.id = id;
    control.value = value;
    if (sys_->ioctl(fd_, VIDIOC_S_CTRL, &control) < 0)
      spdlog::warn("v4l2 camera {}: cannot set {}: {}", settings_.device, what,
                   std::strerror(errno));
  };
  if (settings_.exposure_us) {
    if (hasControl(V4L2_CID_EXPOSURE_ABSOLUTE)) {
      if (hasControl(V4L2_CID_EXPOSURE_AUTO))
        setControl(V4L2_CID_EXPOSURE_AUTO, V4L2_EXPOSURE_MANUAL, "manual exposure");
      // V4L2 counts exposure in units of 100 us.
      setControl(V4L2_CID_EXPOSURE_ABSOLUTE,
                 std::max(1, static_cast<int>(*settings_.exposure_us / 100.0 + 0.5)), "exposure");
    } else {
      spdlog::warn("v4l2 camera {}: no exposure control; exposure left as is", settings_.device);
    }
  }
  if (settings_.gain) {
    if (hasControl(V4L2_CID_GAIN))
      setControl(V4L2_CID_GAIN, *settings_.gain, "gain");
    else
      spdlog::warn("v4l2 camera {}: no gain control; gain left as is", settings_.device);
  }
}

void V4l2Camera::startStreaming() {
  v4l2_requestbuffers request{};
  request.count = static_cast<std::uint32_t>(settings_.buffer_count);
  request.type = V4L2_BUF_TYPE_VIDEO_CAPTURE;
  request.memory = V4L2_MEMORY_MMAP;
  if (sys_->ioctl(fd_, VIDIOC_REQBUFS, &request) < 0) fail("VIDIOC_REQBUFS");
  if (request.count < 2) {
    errno = ENOMEM;
    fail("driver granted fewer than 2 buffers");
  }
  for (std::uint32_t i = 0; i < request.count; ++i) {
    v4l2_buffer buffer{};
    buffer.type = V4L2_BUF_TYPE_VIDEO_CAPTURE;
    buffer.memory = V4L2_MEMORY_MMAP;
    buffer.index = i;
    if (sys_->ioctl(fd_, VIDIOC_QUERYBUF, &buffer) < 0) fail("VIDIOC_QUERYBUF");
    void* data = sys_->mmap(buffer.length, fd_, static_cast<off_t>(buffer.m.offset));
    if (data == MAP_FAILED) fail("mmap");
    buffers_.push_back({data, buffer.length});
    if (sys_->ioctl(fd_, VIDIOC_QBUF, &buffer) < 0) fail("VIDIOC_QBUF");
  }
  v4l2_buf_type type = V4L2_BUF_TYPE_VIDEO_CAPTURE;
  if (sys_->ioctl(fd_, VIDIOC_STREAMON, &type) < 0) fail("VIDIOC_STREAMON");
}

void V4l2Camera::releaseDevice() {
  if (fd_ >= 0 && !lost_) {
    v4l2_buf_type type = V4L2_BUF_TYPE_VIDEO_CAPTURE;
    sys_->ioctl(fd_, VIDIOC_STREAMOFF, &type);
  }
  for (const auto& b : buffers_) sys_->munmap(b.data, b.length);
  buffers_.clear();
  if (fd_ >= 0) {
    if (!lost_) {  // give the buffers back to the driver
      v4l2_requestbuffers request{};
      request.type = V4L2_BUF_TYPE_VIDEO_CAPTURE;
      request.memory = V4L2_MEMORY_MMAP;
      sys_->ioctl(fd_, VIDIOC_REQBUFS, &request);
    }
    sys_->close(fd_);
  }
  fd_ = -1;
}

void V4l2Camera::open() {
  if (fd_ >= 0) return;
  try {
    openDevice();
  } catch (const CameraError&) {
    releaseDevice();
    throw;
  }
  std::lock_guard lock(health_mutex_);
  health_.connected = true;
  spdlog::info("v4l2 camera {}: {} {}x{}", settings_.device, fourcc(), width_, height_);
}

void V4l2Camera::start() {
  if (streaming_) return;
  if (fd_ < 0) throw CameraError("v4l2 camera " + settings_.device + ": start() before open()");
  try {
    startStreaming();
  } catch (const CameraError&) {
    releaseDevice();
    std::lock_guard lock(health_mutex_);
    health_.connected = false;
    throw;
  }
  streaming_ = true;
  ids_.restart();
  std::lock_guard lock(health_mutex_);
  health_.streaming = true;
}

void V4l2Camera::stop() {
  if (!streaming_) return;
  streaming_ = false;
  if (fd_ >= 0) {
    v4l2_buf_type type = V4L2_BUF_TYPE_VIDEO_CAPTURE;
    sys_->ioctl(fd_, VIDIOC_STREAMOFF, &type);
    for (const auto& b : buffers_) sys_->munmap(b.data, b.length);
    buffers_.clear();
    v4l2_requestbuffers request{};
    request.type = V4L2_BUF_TYPE_VIDEO_CAPTURE;
    request.memory = V4L2_MEMORY_MMAP;
    sys_->ioctl(fd_, VIDIOC_REQBUFS, &request);
  }
  std::lock_guard lock(health_mutex_);
  health_.streaming = false;
}

void V4l2Camera::close() {
  stop();
  releaseDevice();
  lost_ = false;
  std::lock_guard lock(health_mutex_);
  health_.connected = false;
}

void V4l2Camera::markLost(const std::string& why) {
  spdlog::error("v4l2 camera {} lost: {}; reconnecting with backoff", settings_.device, why);
  lost_ = true;
  releaseDevice();
  backoff_ = std::chrono::milliseconds(settings_.reconnect_initial_ms);
  next_attempt_ = Clock::now() + backoff_;
  std::lock_guard lock(health_mutex_);
  health_.connected = false;
  health_.last_error = "device lost: " + why;
}

GrabResult V4l2Camera::tryReconnect(Clock::time_point deadline) {
  const std::string message = "v4l2 camera " + settings_.device + " is disconnected";
  if (next_attempt_ > deadline) {
    std::this_thread::sleep_until(deadline);
    return {GrabStatus::Disconnected, {}, message};
  }
  std::this_thread::sleep_until(next_attempt_);
  try {
    openDevice();
    startStreaming();
  } catch (const CameraError& e) {
    releaseDevice();
    backoff_ = std::min(backoff_ * 2, std::chrono::milliseconds(settings_.reconnect_max_ms));
    next_attempt_ = Clock::now() + backoff_;
    std::lock_guard lock(health_mutex_);
    health_.last_error = e.what();
    return {GrabStatus::Disconnected, {}, message + ": " + e.what()};
  }
  lost_ = false;
  ids_.restart();
  spdlog::info("v4l2 camera {} reconnected", settings_.device);
  std::lock_guard lock(health_mutex_);
  health_.connected = true;
  ++health_.reconnects;
  return {GrabStatus::Ok, {}, {}};
}

GrabResult V4l2Camera::grab(std::chrono::milliseconds timeout) {
  const auto deadline = Clock::now() + timeout;
  if (!streaming_) return {GrabStatus::NotStarted, {}, name() + ": not started"};
  if (lost_) {
    GrabResult r = tryReconnect(deadline);
    if (lost_) return r;
  }

  const auto remaining_ms = std::max<std::int64_t>(
      0, std::chrono::duration_cast<std::chrono::milliseconds>(deadline - Clock::now()).count());
  short revents = 0;
  const int ready = sys_->poll(fd_, POLLIN, static_cast<int>(remaining_ms), revents);
  if (ready < 0 && errno != EINTR) {
    markLost(std::string("poll: ") + std::strerror(errno));
    return {GrabStatus::Disconnected, {}, name() + " lost"};
  }
  if (ready > 0 && (revents & (POLLERR | POLLHUP | POLLNVAL))) {
    markLost("poll reports an error");
    return {GrabStatus::Disconnected, {}, name() + " lost"};
  }
  if (ready <= 0 || !(revents & POLLIN)) {
    std::lock_guard lock(health_mutex_);
    ++health_.timeouts;
    return {GrabStatus::Timeout, {}, "no frame within timeout"};
  }

  v4l2_buffer buffer{};
  buffer.type = V4L2_BUF_TYPE_VIDEO_CAPTURE;
  buffer.memory = V4L2_MEMORY_MMAP;
  if (sys_->ioctl(fd_, VIDIOC_DQBUF, &buffer) < 0) {
    if (deviceGone(errno)) {
      markLost(std::string("VIDIOC_DQBUF: ") + std::strerror(errno));
      return {GrabStatus::Disconnected, {}, name() + " lost"};
    }
    std::lock_guard lock(health_mutex_);
    ++health_.timeouts;
    return {GrabStatus::Timeout, {}, std::string("VIDIOC_DQBUF: ") + std::strerror(errno)};
  }

  Frame frame;
  frame.timestamp = std::chrono::system_clock::now();
  frame.device_timestamp_ns = static_cast<std::uint64_t>(buffer.timestamp.tv_sec) * 1000000000ull +
                              static_cast<std::uint64_t>(buffer.timestamp.tv_usec) * 1000ull;
  frame.source = settings_.device;
  const auto step = ids_.next(buffer.sequence);
  frame.id = step.id;

  GrabResult result;
  const std::size_t expected =
      pixel_format_ == V4L2_PIX_FMT_MJPEG ? 1 : static_cast<std::size_t>(bytes_per_line_) * height_;
  if (buffer.index >= buffers_.size() || (buffer.flags & V4L2_BUF_FLAG_ERROR) ||
      buffer.bytesused < expected) {
    frame.complete = false;
    result = {GrabStatus::Incomplete, std::move(frame), "driver flagged or short buffer"};
  } else {
    void* data = buffers_[buffer.index].data;
    if (pixel_format_ == V4L2_PIX_FMT_MJPEG) {
      // Decoding is the copy: the JPEG bytes are read in place.
      const cv::Mat jpeg(1, static_cast<int>(buffer.bytesused), CV_8UC1, data);
      const bool mono = settings_.colour == ColourConversion::Mono;
      frame.image = decodeImage(jpeg, mono ? cv::IMREAD_GRAYSCALE : cv::IMREAD_COLOR);
      frame.format = mono ? PixelFormat::Mono8 : PixelFormat::Bgr8;
      if (frame.image.empty() || frame.image.cols != width_ || frame.image.rows != height_) {
        frame.image.release();
        frame.complete = false;
        result = {GrabStatus::Incomplete, std::move(frame), "corrupt MJPEG frame"};
      } else {
        result = {GrabStatus::Ok, std::move(frame), {}};
      }
    } else {
      const bool yuyv = pixel_format_ == V4L2_PIX_FMT_YUYV;
      const cv::Mat view(height_, width_, yuyv ? CV_8UC2 : CV_8UC1, data,
                         static_cast<std::size_t>(bytes_per_line_));
      frame.image = convertSensorImage(view, yuyv ? SensorLayout::Yuyv : SensorLayout::Mono8,
                                       settings_.colour, frame.format);
      result = {GrabStatus::Ok, std::move(frame), {}};
    }
  }
  if (sys_->ioctl(fd_, VIDIOC_QBUF, &buffer) < 0 && deviceGone(errno)) {
    markLost(std::string("VIDIOC_QBUF: ") + std::strerror(errno));
  }

  std::lock_guard lock(health_mutex_);
  health_.lost_frames += step.lost;
  if (result.status == GrabStatus::Ok) ++health_.frames;
  if (result.status == GrabStatus::Incomplete) ++health_.incomplete_frames;
  return result;
}

CameraHealth V4l2Camera::health() const {
  std::lock_guard lock(health_mutex_);
  return health_;
}

std::string V4l2Camera::name() const {
  return "v4l2:" + settings_.device;
}

std::string V4l2Camera::fourcc() const {
  return fourccText(pixel_format_);
}

}  // namespace facet
