// Reading the image a subcommand was given: the file's own problem in our words ("no such file",
// "not an image file"), never a decoder library's warning on stderr. Decoding goes through the
// replay camera's reader (OpenImageIO, header checked before any pixel is allocated), so the tool
// reads exactly what facetd reads.
#include <fcntl.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <filesystem>
#include <fstream>

#include "algorithms/image/grey_image.hpp"
#include "camera/camera_settings.hpp"
#include "camera/image_file_reader.hpp"
#include "service/cli/command_line.hpp"

namespace facet::cli {
namespace {

// libpng prints its own errors ("libpng error: IDAT: Read error") on stderr before the reader
// returns its error; the tool's message says it in its words, so stderr is closed to the decoder
// while it runs (the tool is single-threaded there).
class QuietStderr {
 public:
  QuietStderr() : saved_(::dup(STDERR_FILENO)) {
    const int null = ::open("/dev/null", O_WRONLY);
    if (null >= 0) {
      ::dup2(null, STDERR_FILENO);
      ::close(null);
    }
  }
  ~QuietStderr() {
    if (saved_ < 0) return;
    ::dup2(saved_, STDERR_FILENO);
    ::close(saved_);
  }
  QuietStderr(const QuietStderr&) = delete;
  QuietStderr& operator=(const QuietStderr&) = delete;

 private:
  int saved_;
};

}  // namespace

cv::Mat readGreyImage(const std::string& path) {
  namespace fs = std::filesystem;
  std::error_code ec;
  const fs::file_status status = fs::status(path, ec);
  if (!fs::exists(status)) throw InputError(path + ": no such file");
  if (fs::is_directory(status)) throw InputError(path + ": is a folder, not an image file");
  if (const std::ifstream probe(path); !probe)
    throw InputError(path + ": cannot open: " + std::strerror(errno));
  ImageFileContent content;
  {
    const QuietStderr quiet;
    content = readImageFile(path, ReplaySettings{}.max_pixels);
  }
  // The decoder's first line says it; the rest repeats it in the library's words.
  if (!content.ok()) throw InputError(content.error.substr(0, content.error.find('\n')));
  return toGrey(content.image);
}

}  // namespace facet::cli
