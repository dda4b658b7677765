#pragma once
// A scripted V4L2 capture device behind the V4l2Syscalls seam: it answers the ioctls a UVC
// driver answers (capabilities, formats, controls, mmap buffers, queue/dequeue, stream on/off),
// delivers the frames a test queues, and can disappear (ENODEV) and come back.

#include <linux/videodev2.h>
#include <poll.h>
#include <sys/mman.h>

#include <cerrno>
#include <cstring>
#include <deque>
#include <map>
#include <set>
#include <vector>

#include "camera/v4l2_syscalls.hpp"

namespace facet::test {

class ScriptedV4l2Device final : public V4l2Syscalls {
 public:
  struct ScriptedFrame {
    std::vector<std::uint8_t> bytes;
    bool error_flag = false;
  };

  std::string path = "/dev/video7";
  std::vector<std::uint32_t> formats = {V4L2_PIX_FMT_YUYV, V4L2_PIX_FMT_GREY, V4L2_PIX_FMT_MJPEG};
  std::uint32_t max_width = 640;  // S_FMT clamps to this, as drivers do
  std::uint32_t max_height = 480;
  std::uint32_t row_padding = 0;  // extra bytes per line for uncompressed formats
  std::map<std::uint32_t, std::int32_t> controls = {
      {V4L2_CID_EXPOSURE_AUTO, 3}, {V4L2_CID_EXPOSURE_ABSOLUTE, 156}, {V4L2_CID_GAIN, 0}};
  std::uint32_t next_sequence = 0;
  std::uint32_t granted_buffers = 0;  // 0: grant what is asked

  // Observations for the tests.
  v4l2_pix_format format{};
  int open_count = 0;
  int live_mappings() const { return static_cast<int>(mapped_.size()); }
  bool streaming() const { return streaming_; }
  std::size_t queued() const { return queue_.size(); }
  std::size_t buffer_count() const { return buffers_.size(); }

  void push(ScriptedFrame frame) { script_.push_back(std::move(frame)); }
  void disappear() { present_ = false; }
  void reappear() {
    present_ = true;
    streaming_ = false;
    queue_.clear();
  }

  int open(const std::string& p, int) override {
    if (!present_ || p != path) return fail(ENOENT);
    ++open_count;
    fd_open_ = true;
    return kFd;
  }
  int close(int fd) override {
    if (fd != kFd || !fd_open_) return fail(EBADF);
    fd_open_ = false;
    streaming_ = false;
    queue_.clear();
    return 0;
  }

  int ioctl(int fd, unsigned long request, void* arg) override {
    if (fd != kFd || !fd_open_) return fail(EBADF);
    if (!present_) return fail(ENODEV);
    switch (request) {
      case VIDIOC_QUERYCAP: {
        auto* cap = static_cast<v4l2_capability*>(arg);
        std::memset(cap, 0, sizeof *cap);
        std::strcpy(reinterpret_cast<char*>(cap->driver), "scripted");
        cap->device_caps = V4L2_CAP_VIDEO_CAPTURE | V4L2_CAP_STREAMING;
        cap->capabilities = cap->device_caps | V4L2_CAP_DEVICE_CAPS;
        return 0;
      }
      case VIDIOC_ENUM_FMT: {
        auto* desc = static_cast<v4l2_fmtdesc*>(arg);
        if (desc->index >= formats.size()) return fail(EINVAL);
        desc->pixelformat = formats[desc->index];
        return 0;
      }
      case VIDIOC_G_FMT: {
        auto* f = static_cast<v4l2_format*>(arg);
        if (format.width == 0) setFormat(formats.front(), 320, 240);
        f->fmt.pix = format;
        return 0;
      }
      case VIDIOC_S_FMT: {
        if (streaming_) return fail(EBUSY);
        auto* f = static_cast<v4l2_format*>(arg);
        std::uint32_t pf = f->fmt.pix.pixelformat;
        bool known = false;
        for (auto o : formats) known |= o == pf;
        if (!known) pf = formats.front();  // drivers substitute, they do not refuse
        setFormat(pf, std::min(f->fmt.pix.width, max_width),
                  std::min(f->fmt.pix.height, max_height));
        f->fmt.pix = format;
        return 0;
      }
      case VIDIOC_QUERYCTRL: {
        auto* q = static_cast<v4l2_queryctrl*>(arg);
        if (!controls.count(q->id)) return fail(EINVAL);
        q->flags = 0;
        return 0;
      }
      case VIDIOC_S_CTRL: {
        auto* c = static_cast<v4l2_control*>(arg);
        if (!controls.count(c->id)) return fail(EINVAL);
        controls[c->id] = c->value;
        return 0;
      }
      case VIDIOC_REQBUFS: {
        auto* r = static_cast<v4l2_requestbuffers*>(arg);
        if (r->memory != V4L2_MEMORY_MMAP) return fail(EINVAL);
        if (streaming_ || !mapped_.empty()) return fail(EBUSY);
        const std::uint32_t n = r->count == 0 ? 0 : (granted_buffers ? granted_buffers : r->count);
        buffers_.assign(n, std::vector<std::uint8_t>(format.sizeimage));
        queue_.clear();
        r->count = n;
        return 0;
      }
      case VIDIOC_QUERYBUF: {
        auto* b = static_cast<v4l2_buffer*>(arg);
        if (b->index >= buffers_.size()) return fail(EINVAL);
        b->length = static_cast<std::uint32_t>(buffers_[b->index].size());
        b->m.offset = b->index * kOffsetStep;
        return 0;
      }
      case VIDIOC_QBUF: {
        auto* b = static_cast<v4l2_buffer*>(arg);
        if (b->index >= buffers_.size()) return fail(EINVAL);
        for (auto q : queue_)
          if (q == b->index) return fail(EINVAL);  // queued twice: a driver refuses it
        queue_.push_back(b->index);
        return 0;
      }
      case VIDIOC_DQBUF: {
        auto* b = static_cast<v4l2_buffer*>(arg);
        if (!streaming_ || queue_.empty() || script_.empty()) return fail(EAGAIN);
        const std::uint32_t index = queue_.front();
        queue_.pop_front();
        ScriptedFrame frame = std::move(script_.front());
        script_.pop_front();
        auto& memory = buffers_[index];
        const std::size_t n = std::min(memory.size(), frame.bytes.size());
        std::memcpy(memory.data(), frame.bytes.data(), n);
        b->index = index;
        b->bytesused = static_cast<std::uint32_t>(n);
        b->flags = frame.error_flag ? V4L2_BUF_FLAG_ERROR : 0;
        b->sequence = next_sequence++;
        b->timestamp.tv_sec = 1;
        b->timestamp.tv_usec = static_cast<long>(b->sequence % 1000000);
        return 0;
      }
      case VIDIOC_STREAMON:
        streaming_ = true;
        return 0;
      case VIDIOC_STREAMOFF:
        streaming_ = false;
        queue_.clear();
        return 0;
      default:
        return fail(ENOTTY);
    }
  }

  void* mmap(std::size_t length, int fd, off_t offset) override {
    if (fd != kFd || !fd_open_) return failMap(EBADF);
    if (!present_) return failMap(ENODEV);
    const std::size_t index = static_cast<std::size_t>(offset) / kOffsetStep;
    if (index >= buffers_.size() || length != buffers_[index].size()) return failMap(EINVAL);
    void* address = buffers_[index].data();
    mapped_.insert(address);
    return address;
  }

  int munmap(void* address, std::size_t) override {
    if (!mapped_.erase(address)) return fail(EINVAL);
    return 0;
  }

  int poll(int fd, short, int, short& revents) override {
    revents = 0;
    if (fd != kFd || !fd_open_) {
      revents = POLLNVAL;
      return 1;
    }
    if (!present_) {
      revents = POLLERR;
      return 1;
    }
    if (streaming_ && !queue_.empty() && !script_.empty()) {
      revents = POLLIN;
      return 1;
    }
    return 0;  // a real poll would wait; the script has nothing more to deliver
  }

 private:
  static constexpr int kFd = 42;
  static constexpr std::size_t kOffsetStep = 1 << 24;

  static int fail(int error) {
    errno = error;
    return -1;
  }
  static void* failMap(int error) {
    errno = error;
    return MAP_FAILED;
  }

  void setFormat(std::uint32_t pf, std::uint32_t width, std::uint32_t height) {
    format = {};
    format.pixelformat = pf;
    format.width = width;
    format.height = height;
    format.field = V4L2_FIELD_NONE;
    if (pf == V4L2_PIX_FMT_MJPEG) {
      format.bytesperline = 0;
      format.sizeimage = width * height * 2;
    } else {
      format.bytesperline = width * (pf == V4L2_PIX_FMT_YUYV ? 2 : 1) + row_padding;
      format.sizeimage = format.bytesperline * height;
    }
  }

  bool present_ = true;
  bool fd_open_ = false;
  bool streaming_ = false;
  std::vector<std::vector<std::uint8_t>> buffers_;
  std::deque<std::uint32_t> queue_;
  std::deque<ScriptedFrame> script_;
  std::set<void*> mapped_;
};

}  // namespace facet::test
