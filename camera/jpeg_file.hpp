#pragma once
// JPEG files read in the process with libjpeg, without the image-codec module (image_codecs.hpp).
// Photographs of parts come as JPEG; loading the module for one cost each `facet` image command
// ~0.35 s, ten times the work of a search. libjpeg is the library OpenCV's own JPEG reader
// drives, so with the same settings the pixels are the ones cv::imread gives, bit for bit.
//
// Only plain files are read here: 8-bit grey or three-component colour, with their Huffman
// tables, within the pixel limit. Anything else (CMYK, Motion-JPEG frames without tables, any
// error or warning of the library) is left to the module, which reads every format and words
// every error. The Exif orientation is reported, not applied: the caller turns what needs it.

#include <cstdint>
#include <filesystem>
#include <optional>

#include <opencv2/core/mat.hpp>

namespace facet {

struct PlainJpeg {
  cv::Mat pixels;  // CV_8UC1, or CV_8UC3 in OpenCV's order (BGR), as stored
  // The orientation cv::imread applies to any read but IMREAD_UNCHANGED: that of the Exif block
  // in the first APP1 segment, which is where OpenCV looks (exif_orientation.hpp); 1 without
  // one. Empty when that segment is not an Exif block read the same way everywhere.
  std::optional<int> orientation = 1;
};

enum class JpegOutput {
  Stored,  // as the file holds it: grey for one component, BGR for three
  Grey,    // grey as libjpeg makes it from any of them (cv::IMREAD_GRAYSCALE)
};

// Empty when the file is not a plain JPEG (see above), cannot be read or holds more than
// `maxPixels` pixels.
std::optional<PlainJpeg> readPlainJpeg(const std::filesystem::path& file, std::uint64_t maxPixels,
                                       JpegOutput output);

}  // namespace facet
