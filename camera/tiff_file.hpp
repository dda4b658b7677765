#pragma once
// TIFF files read in the process with libtiff, without the image-codec module (image_codecs.hpp).
// Industrial cameras' recording tools write TIFF, often 16-bit grey; loading the module for one
// cost each `facet` image command ~0.35 s, ten times the work of a search. libtiff is the library
// both of the module's readers (OpenCV, OpenImageIO) drive, and for the files read here they
// return the stored samples as they are, so the pixels are theirs, bit for bit.
//
// Only plain files are read here: the first image of the file, grey (min-is-black) or RGB,
// 8 or 16 bits of unsigned integer per sample, no extra samples (alpha), samples interleaved,
// stored top-left first, uncompressed or compressed losslessly (LZW, Deflate, PackBits), in
// strips or tiles. Anything else (palette, min-is-white, YCbCr, JPEG inside TIFF, floats, other
// orientations) and any error or warning of the library is left to the module, which reads every
// format and words every error.

#include <cstdint>
#include <filesystem>
#include <optional>

#include <opencv2/core/mat.hpp>

#include "camera/stored_layout_filter.hpp"

namespace facet {

// CV_8UC1 or CV_16UC1 for grey; CV_8UC3 or CV_16UC3 in OpenCV's order (BGR) for colour. Empty
// when the file is not a plain TIFF (see above) whose layout `wanted` accepts (an empty filter
// accepts every one), cannot be read or holds more than `maxPixels` pixels.
std::optional<cv::Mat> readPlainTiff(const std::filesystem::path& file, std::uint64_t maxPixels,
                                     const StoredLayoutFilter& wanted = {});

}  // namespace facet
