#include "camera/image_file_decoder.hpp"

#include <OpenImageIO/imageio.h>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "camera/decoded_frame.hpp"

namespace facet {
namespace OIIO = OIIO_NAMESPACE;

ImageFileContent decodeImageFile(const std::filesystem::path& file, std::uint64_t max_pixels) {
  ImageFileContent content;
  const std::string name = file.string();
  auto input = OIIO::ImageInput::open(name);
  if (!input) {
    content.error = name + ": cannot read image: " + OIIO::geterror();
    return content;
  }
  const OIIO::ImageSpec& spec = input->spec();
  const std::uint64_t pixels =
      static_cast<std::uint64_t>(std::max(spec.width, 0)) * std::max(spec.height, 0);
  if (spec.width <= 0 || spec.height <= 0 || spec.depth > 1 || spec.nchannels <= 0) {
    content.error = name + ": unsupported image geometry " + std::to_string(spec.width) + "x" +
                    std::to_string(spec.height) + "x" + std::to_string(spec.nchannels);
    return content;
  }
  if (pixels > max_pixels) {
    content.error = name + ": " + std::to_string(spec.width) + "x" + std::to_string(spec.height) +
                    " exceeds the limit of " + std::to_string(max_pixels) + " pixels";
    return content;
  }
  const bool eight_bit = spec.format.size() == 1;
  const OIIO::TypeDesc type = eight_bit ? OIIO::TypeDesc::UINT8 : OIIO::TypeDesc::UINT16;
  // Grey and grey+alpha keep one channel; colour keeps three; alpha is dropped.
  const int channels = spec.nchannels >= 3 ? 3 : 1;
  if (std::string_view(input->format_name()) == "pnm") {
    // OpenImageIO 2.4's PNM reader returns v-1 for 16-bit values above 32768 and is ~20x slower
    // than OpenCV's on raw PGM; OpenImageIO has checked the header above, OpenCV reads pixels.
    input->close();
    content.image = cv::imread(name, cv::IMREAD_UNCHANGED);
    if (content.image.empty() || content.image.cols != spec.width ||
        content.image.rows != spec.height) {
      content.image.release();
      content.error = name + ": corrupt or truncated image";
      return content;
    }
    return frameOfDecodedPixels(std::move(content.image));
  }
  content.image.create(spec.height, spec.width, CV_MAKETYPE(eight_bit ? CV_8U : CV_16U, channels));
  if (!input->read_image(0, 0, 0, channels, type, content.image.data)) {
    content.error = name + ": corrupt or truncated image: " + input->geterror();
    content.image.release();
    return content;
  }
  if (channels == 3) cv::cvtColor(content.image, content.image, cv::COLOR_RGB2BGR);  // in place
  return frameOfDecodedPixels(std::move(content.image));
}

}  // namespace facet
