// Reading the image a subcommand was given: the file's own problem in our words ("no such file",
// "not an image file"), never a decoder library's warning on stderr. Decoding goes through the
// replay camera's reader (OpenImageIO, header checked before any pixel is allocated), so the tool
// reads exactly what facetd reads.
#include <cerrno>
#include <cstring>
#include <filesystem>
#include <fstream>

#include <opencv2/imgproc.hpp>

#include "camera/camera_settings.hpp"
#include "camera/image_file_reader.hpp"
#include "service/cli/command_line.hpp"

namespace facet::cli {

cv::Mat readGreyImage(const std::string& path) {
  namespace fs = std::filesystem;
  std::error_code ec;
  const fs::file_status status = fs::status(path, ec);
  if (!fs::exists(status)) throw InputError(path + ": no such file");
  if (fs::is_directory(status)) throw InputError(path + ": is a folder, not an image file");
  if (const std::ifstream probe(path); !probe)
    throw InputError(path + ": cannot open: " + std::strerror(errno));
  ImageFileContent content = readImageFile(path, ReplaySettings{}.max_pixels);
  if (!content.ok()) throw InputError(content.error);
  if (content.image.channels() == 3) cv::cvtColor(content.image, content.image, cv::COLOR_BGR2GRAY);
  return content.image;
}

}  // namespace facet::cli
