#pragma once
// The interface between the image-codec facade (image_codecs.cpp) and the module that implements
// it (libfacet_image_codecs.so, image_codecs_module.cpp). The module links OpenImageIO and
// OpenCV's imgcodecs, which cost ~0.3 s and ~200 shared libraries at start-up; only the commands
// that read or write image files load it.
//
// Both sides are built together by this project with one compiler and one OpenCV, so the table
// passes C++ types; `abi` guards against a module left over from another build.

#include <cstdint>
#include <filesystem>
#include <string>
#include <vector>

#include <opencv2/core/mat.hpp>

#include "camera/image_file_reader.hpp"

namespace facet {

// Raise whenever a member or a signature below changes.
inline constexpr int kImageCodecAbi = 1;

struct ImageCodecTable {
  int abi = kImageCodecAbi;
  // readImageFile (image_file_reader.hpp): header checked against the pixel limit first.
  ImageFileContent (*readFile)(const std::filesystem::path& file, std::uint64_t max_pixels);
  // cv::imread, cv::imwrite, cv::imencode, cv::imdecode.
  cv::Mat (*read)(const std::string& file, int flags);
  bool (*write)(const std::string& file, const cv::Mat& image, const std::vector<int>& params);
  bool (*encode)(const std::string& ext, const cv::Mat& image, std::vector<unsigned char>& bytes,
                 const std::vector<int>& params);
  cv::Mat (*decode)(const cv::Mat& bytes, int flags);
};

}  // namespace facet

// The module's one exported symbol.
extern "C" const facet::ImageCodecTable* facet_image_codec_table();
inline constexpr const char* kImageCodecEntry = "facet_image_codec_table";
