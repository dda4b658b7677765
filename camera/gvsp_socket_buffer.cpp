#include "camera/gvsp_socket_buffer.hpp"

#include <netinet/in.h>
#include <sys/socket.h>

#include <algorithm>
#include <exception>
#include <filesystem>
#include <string>

#include <spdlog/spdlog.h>

namespace facet {

// Aravis sizes its GVSP socket's receive buffer (socket-buffer auto) only when the first
// packet of the first frame arrives, so that frame's burst meets the system default buffer and,
// from a fast sender (a camera on loopback, 10 GigE), loses packets: the first part after every
// (re)connection would be an incomplete frame. Aravis 0.8 does not expose the socket, so it is
// found among our descriptors by the stream's local UDP port and given the frame size now.
void presizeStreamSocket(ArvStream* stream, guint payload) {
  if (!ARV_IS_GV_STREAM(stream)) return;
  const guint16 port = arv_gv_stream_get_port(ARV_GV_STREAM(stream));
  const int size = static_cast<int>(std::min<guint>(payload, 1u << 30));
  std::error_code error;
  for (const auto& entry : std::filesystem::directory_iterator("/proc/self/fd", error)) {
    int fd = -1;
    try {
      fd = std::stoi(entry.path().filename().string());
    } catch (const std::exception&) {
      continue;
    }
    sockaddr_in address{};
    socklen_t length = sizeof address;
    int type = 0;
    socklen_t type_length = sizeof type;
    if (getsockname(fd, reinterpret_cast<sockaddr*>(&address), &length) != 0 ||
        address.sin_family != AF_INET || ntohs(address.sin_port) != port ||
        getsockopt(fd, SOL_SOCKET, SO_TYPE, &type, &type_length) != 0 || type != SOCK_DGRAM)
      continue;
    if (setsockopt(fd, SOL_SOCKET, SO_RCVBUF, &size, sizeof size) != 0)
      spdlog::debug("GVSP socket: cannot set a {} byte receive buffer", size);
  }
}

}  // namespace facet
