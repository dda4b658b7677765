#pragma once
// The rule by which a decoded image file becomes a Frame's pixels, shared by the in-process PNG
// reader and the image-codec module so that both give the same frame for the same file.

#include <opencv2/core/mat.hpp>

#include "camera/image_file_reader.hpp"

namespace facet {

// `decoded`: 1 to 4 channels as stored (grey, grey+alpha, BGR, BGRA), CV_8U or CV_16U. Alpha is
// dropped; grey keeps its depth; colour becomes 8-bit BGR, a Frame's only colour format.
ImageFileContent frameOfDecodedPixels(cv::Mat decoded);

}  // namespace facet
