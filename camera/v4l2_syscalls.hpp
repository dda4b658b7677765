#pragma once
// The kernel calls the V4L2 backend makes, behind a thin interface: the real one forwards to
// the kernel; tests script a device (there is no /dev/video on CI machines). Every call reports
// failure the way the kernel does: -1 (or MAP_FAILED) with errno set.

#include <sys/types.h>

#include <cstddef>
#include <memory>
#include <string>

namespace facet {

class V4l2Syscalls {
 public:
  virtual ~V4l2Syscalls() = default;
  virtual int open(const std::string& path, int flags) = 0;
  virtual int close(int fd) = 0;
  virtual int ioctl(int fd, unsigned long request, void* argument) = 0;
  // mmap(nullptr, length, PROT_READ | PROT_WRITE, MAP_SHARED, fd, offset)
  virtual void* mmap(std::size_t length, int fd, off_t offset) = 0;
  virtual int munmap(void* address, std::size_t length) = 0;
  // poll() on one descriptor; `revents` receives the returned events.
  virtual int poll(int fd, short events, int timeout_ms, short& revents) = 0;
};

// The kernel itself.
std::shared_ptr<V4l2Syscalls> kernelV4l2Syscalls();

}  // namespace facet
