#pragma once
// Image files and in-memory PNG/JPEG for production code, through a module loaded on first use
// (libfacet_image_codecs.so: OpenImageIO and OpenCV's imgcodecs). Linking those two directly
// made every start of `facet` and `facetd` take ~0.3 s and map ~200 more shared libraries,
// also for the commands that never touch an image file. Plain PNG, JPEG, TIFF and BMP files and
// binary PGMs are read without the module (png_file.hpp, jpeg_file.hpp, tiff_file.hpp,
// bmp_file.hpp, pgm_file.hpp), with the same result, and PNGs of 8- or 16-bit grey, BGR and BGRA
// images are written and encoded without it when no parameters are given (png_writer.hpp).
//
// Each function behaves like its OpenCV namesake (flags are cv::ImreadModes, params
// cv::ImwriteFlags; only the constants of <opencv2/imgcodecs.hpp> are used here). Thread-safe;
// the module is loaded once. When it cannot be loaded, reading gives an empty image and writing
// or encoding gives false, as for an unreadable file, and the reason is printed once on stderr
// (readImageFile also puts it in its error). The module is looked for in FACET_IMAGE_CODECS (a
// file, then the only place tried), else beside the executable's install layout
// (<bin>/../lib/facet/), else in the build tree that built this program.

#include <filesystem>
#include <string>
#include <vector>

#include <opencv2/core/mat.hpp>
#include <opencv2/imgcodecs.hpp>

namespace facet {

cv::Mat readImage(const std::filesystem::path& file, int flags = cv::IMREAD_UNCHANGED);
bool writeImage(const std::filesystem::path& file, const cv::Mat& image,
                const std::vector<int>& params = {});
// `ext` names the format as cv::imencode's does: ".png", ".jpg".
bool encodeImage(const std::string& ext, const cv::Mat& image, std::vector<unsigned char>& bytes,
                 const std::vector<int>& params = {});
// `bytes`: one row of CV_8U holding the encoded file.
cv::Mat decodeImage(const cv::Mat& bytes, int flags);

// Loads the module if that was not tried yet. Empty when it is loaded; otherwise why not: every
// path tried with dlerror()'s words.
const std::string& imageCodecsProblem();

}  // namespace facet
