#pragma once
// Bytes of bad image files, as an operator might copy them into a replay folder: headers that
// announce huge images with almost no pixel data behind them. Used by the camera-level replay
// tests (tests/hardening) and by the daemon-level ones (tests/daemon).

#include <cstdint>
#include <string>

#include <opencv2/core.hpp>

namespace facet::test {

// `image` encoded by OpenCV for the extension `ext` (".png", ".bmp", ...).
std::string encodeImage(const std::string& ext, const cv::Mat& image);

// A PNG chunk with a correct CRC, so that only what it announces can be wrong.
std::string pngChunk(const std::string& type, const std::string& data);

// A PNG whose IHDR announces width x height (bit depth, colour type) followed by a few bytes of
// pixel data: what a hostile or corrupt file looks like.
std::string pngHeaderOnly(std::uint32_t width, std::uint32_t height, char depth, char colour);

}  // namespace facet::test
