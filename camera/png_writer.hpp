#pragma once
// PNGs encoded in the process with libpng, without the image-codec module (image_codecs.hpp).
// facetd writes PNGs for its image archive (failed parts) and its dashboard's picture; through
// the module the first of them cost 0.4 s of dynamic linking, in the middle of production: the
// publishing thread held the PLC results of the next ten parts back and took a core from their
// inspection (bench_daemon's first parts). libpng is the library OpenCV's encoder uses, with
// OpenCV's default settings here (zlib level 1, run-length strategy, the Sub filter), so a
// picture decodes to the same pixels either way.
//
// Encoded here: 8 or 16 bits per channel, 1, 3 or 4 channels (grey, BGR, BGRA as OpenCV orders
// colour). Anything else is left to the module.

#include <optional>
#include <vector>

#include <opencv2/core/mat.hpp>

namespace facet {

// The PNG file of `image`, or nullopt for an image this encoder does not take (see above) or a
// libpng failure (no memory).
std::optional<std::vector<unsigned char>> encodePlainPng(const cv::Mat& image);

}  // namespace facet
