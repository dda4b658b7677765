#pragma once
// The Exif orientation of a photograph, and the turn cv::imread gives its pixels for it. Cameras
// and phones write an Exif block into nearly every JPEG; cv::imread applies its orientation to
// every read but IMREAD_UNCHANGED. Reading it here lets a grey read of a camera's JPEG stay in
// the process (jpeg_file.hpp) instead of loading the image-codec module for it.

#include <cstddef>
#include <optional>

#include <opencv2/core/mat.hpp>

namespace facet {

// The orientation (TIFF tag 274 in the first image directory, 1 to 8) of an Exif block: the
// payload of a JPEG APP1 segment, "Exif\0\0" then a TIFF header. 1 when the block is well formed
// and has no orientation. Empty when it is not a block read the same way by every reader:
// damaged or truncated, not Exif, an orientation that is not one SHORT from 1 to 8, or given
// twice.
std::optional<int> exifOrientation(const unsigned char* block, std::size_t size);

// Turns `image` (as stored) the way cv::imread does for `orientation` (1 to 8; 1 leaves it).
void applyExifOrientation(cv::Mat& image, int orientation);

}  // namespace facet
