// The image-codec module (libfacet_image_codecs.so): the table that image_codecs.cpp loads. The
// only exported symbol is its entry point; everything else stays inside the module.
#include <opencv2/imgcodecs.hpp>

#include "camera/image_codec_table.hpp"
#include "camera/image_file_decoder.hpp"

namespace facet {
namespace {

cv::Mat read(const std::string& file, int flags) {
  return cv::imread(file, flags);
}

bool write(const std::string& file, const cv::Mat& image, const std::vector<int>& params) {
  return cv::imwrite(file, image, params);
}

bool encode(const std::string& ext, const cv::Mat& image, std::vector<unsigned char>& bytes,
            const std::vector<int>& params) {
  return cv::imencode(ext, image, bytes, params);
}

cv::Mat decode(const cv::Mat& bytes, int flags) {
  return cv::imdecode(bytes, flags);
}

constexpr ImageCodecTable kTable{
    .abi = kImageCodecAbi,
    .readFile = decodeImageFile,
    .read = read,
    .write = write,
    .encode = encode,
    .decode = decode,
};

}  // namespace
}  // namespace facet

extern "C" __attribute__((visibility("default"))) const facet::ImageCodecTable*
facet_image_codec_table() {
  return &facet::kTable;
}
