#pragma once
// readImageFile's implementation inside the image-codec module (OpenImageIO, OpenCV for PNM).
// Production code calls readImageFile (image_file_reader.hpp), which loads the module.

#include <cstdint>
#include <filesystem>

#include "camera/image_file_reader.hpp"

namespace facet {

ImageFileContent decodeImageFile(const std::filesystem::path& file, std::uint64_t max_pixels);

}  // namespace facet
