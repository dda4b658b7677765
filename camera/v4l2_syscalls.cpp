#include "camera/v4l2_syscalls.hpp"

#include <fcntl.h>
#include <poll.h>
#include <sys/ioctl.h>
#include <sys/mman.h>
#include <unistd.h>

#include <cerrno>

namespace facet {
namespace {

class KernelV4l2Syscalls final : public V4l2Syscalls {
 public:
  int open(const std::string& path, int flags) override { return ::open(path.c_str(), flags); }
  int close(int fd) override { return ::close(fd); }
  int ioctl(int fd, unsigned long request, void* argument) override {
    int r;
    do r = ::ioctl(fd, request, argument);
    while (r == -1 && errno == EINTR);
    return r;
  }
  void* mmap(std::size_t length, int fd, off_t offset) override {
    return ::mmap(nullptr, length, PROT_READ | PROT_WRITE, MAP_SHARED, fd, offset);
  }
  int munmap(void* address, std::size_t length) override { return ::munmap(address, length); }
  int poll(int fd, short events, int timeout_ms, short& revents) override {
    pollfd p{fd, events, 0};
    const int r = ::poll(&p, 1, timeout_ms);
    revents = p.revents;
    return r;
  }
};

}  // namespace

std::shared_ptr<V4l2Syscalls> kernelV4l2Syscalls() {
  static auto kernel = std::make_shared<KernelV4l2Syscalls>();
  return kernel;
}

}  // namespace facet
