#pragma once
// V4L2 pixel formats as four-character codes ("GREY", "YUYV", "MJPG") and back.

#include <cstdint>
#include <string>

namespace facet {

inline std::string fourccText(std::uint32_t code) {
  std::string s(4, ' ');
  for (int i = 0; i < 4; ++i) s[i] = static_cast<char>((code >> (8 * i)) & 0xFF);
  return s;
}

// 0 for a text that is not four characters long.
inline std::uint32_t fourccOf(const std::string& s) {
  if (s.size() != 4) return 0;
  std::uint32_t code = 0;
  for (int i = 0; i < 4; ++i)
    code |= static_cast<std::uint32_t>(static_cast<unsigned char>(s[i])) << (8 * i);
  return code;
}

}  // namespace facet
