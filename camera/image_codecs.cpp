#include "camera/image_codecs.hpp"

#include <cctype>
#include <cstdio>
#include <fstream>
#include <optional>

#include <opencv2/imgproc.hpp>

#include "camera/bmp_file.hpp"
#include "camera/decoded_frame.hpp"
#include "camera/exif_orientation.hpp"
#include "camera/image_codec_table.hpp"
#include "camera/image_file_reader.hpp"
#include "camera/jpeg_file.hpp"
#include "camera/module_file.hpp"
#include "camera/pgm_file.hpp"
#include "camera/png_file.hpp"
#include "camera/png_writer.hpp"
#include "camera/tiff_file.hpp"

// Baked in by camera/CMakeLists.txt.
#ifndef FACET_IMAGE_CODECS_FILE
#error "FACET_IMAGE_CODECS_FILE (the module's file name) is not defined"
#endif

namespace facet {
namespace {
namespace fs = std::filesystem;

struct LoadedCodecs {
  const ImageCodecTable* table = nullptr;
  std::string problem;  // empty when `table` is set
};

LoadedCodecs load() {
  const ModuleFile module{"FACET_IMAGE_CODECS", FACET_IMAGE_CODECS_FILE,
                          FACET_IMAGE_CODECS_FROM_BIN, FACET_IMAGE_CODECS_BUILD_PATH};
  std::string tried;
  if (const auto* table =
          openModuleTable<ImageCodecTable>(module, kImageCodecEntry, kImageCodecAbi, tried))
    return {table, {}};
  LoadedCodecs failed;
  failed.problem = "image codecs not loaded (set FACET_IMAGE_CODECS to the module " +
                   std::string(FACET_IMAGE_CODECS_FILE) + "); tried " + tried;
  std::fprintf(stderr, "facet: %s\n", failed.problem.c_str());
  return failed;
}

const LoadedCodecs& loaded() {
  static const LoadedCodecs codecs = load();  // once, thread-safe
  return codecs;
}

// OpenCV's own limit on the pixels cv::imread decodes (CV_IO_MAX_IMAGE_PIXELS' default).
constexpr std::uint64_t kImreadMaxPixels = std::uint64_t{1} << 30;

// The cv::imread flags the in-process readers serve: as stored, or grey (any depth asked or not).
// Every other read goes to the module.
enum class PlainRead { Unchanged, Grey, Other };
PlainRead plainReadOf(int flags) {
  if (flags == cv::IMREAD_UNCHANGED) return PlainRead::Unchanged;
  if (flags == cv::IMREAD_GRAYSCALE || flags == (cv::IMREAD_GRAYSCALE | cv::IMREAD_ANYDEPTH))
    return PlainRead::Grey;
  return PlainRead::Other;
}

// cv::imread's result for a plain PNG, where it is the file's pixels as stored: the flags
// facet reads with, and no conversion or EXIF orientation to apply.
std::optional<cv::Mat> imreadOfPlainPng(const fs::path& file, int flags) {
  const PlainRead read = plainReadOf(flags);
  if (read == PlainRead::Other) return std::nullopt;
  const bool unchanged = read == PlainRead::Unchanged, grey = read == PlainRead::Grey;
  // OpenCV gives grey+alpha as BGRA, and a grey read of a deep file as 8 bits unless asked.
  const auto stored = [&](int type) {
    if (unchanged) return CV_MAT_CN(type) != 2;
    return CV_MAT_CN(type) == 1 && (CV_MAT_DEPTH(type) == CV_8U || (flags & cv::IMREAD_ANYDEPTH));
  };
  auto png = readPlainPng(file, kImreadMaxPixels, stored);
  if (!png || (grey && png->hasExif)) return std::nullopt;
  return std::move(png->pixels);
}

// cv::imread's result for a plain JPEG: the flags facet reads with, and the Exif orientation
// applied as cv::imread applies it to any read but IMREAD_UNCHANGED.
std::optional<cv::Mat> imreadOfPlainJpeg(const fs::path& file, int flags) {
  const PlainRead read = plainReadOf(flags);
  if (read == PlainRead::Other) return std::nullopt;
  const bool grey = read == PlainRead::Grey;
  auto jpeg = readPlainJpeg(file, kImreadMaxPixels, grey ? JpegOutput::Grey : JpegOutput::Stored);
  if (!jpeg || (grey && !jpeg->orientation)) return std::nullopt;
  if (grey) applyExifOrientation(jpeg->pixels, *jpeg->orientation);
  return std::move(jpeg->pixels);
}

// The layouts that cv::imread gives as stored for files whose colour it takes as it is (TIFF,
// BMP): every layout read unchanged; grey ones read as grey, 8 bits or any depth when asked. A
// colour file read as grey, or a 16-bit one read as 8 bits, follows OpenCV's own rules: the
// module.
StoredLayoutFilter storedAsRead(PlainRead read, int flags) {
  return [read, flags](int type) {
    return read == PlainRead::Unchanged ||
           (CV_MAT_CN(type) == 1 && (CV_MAT_DEPTH(type) == CV_8U || (flags & cv::IMREAD_ANYDEPTH)));
  };
}

// cv::imread's result for a plain TIFF: the stored samples, read as stored or, for a grey file,
// as grey (8 bits, or 16 when any depth is asked). A colour file read as grey, or a 16-bit one
// read as 8 bits, is converted by OpenCV's own rules: the module.
std::optional<cv::Mat> imreadOfPlainTiff(const fs::path& file, int flags) {
  const PlainRead read = plainReadOf(flags);
  if (read == PlainRead::Other) return std::nullopt;
  return readPlainTiff(file, kImreadMaxPixels, storedAsRead(read, flags));
}

// cv::imread's result for a plain BMP: the stored pixels, read as stored or, for a grey file, as
// grey. A colour file read as grey is converted by OpenCV's own rules: the module.
std::optional<cv::Mat> imreadOfPlainBmp(const fs::path& file, int flags) {
  const PlainRead read = plainReadOf(flags);
  if (read == PlainRead::Other) return std::nullopt;
  return readPlainBmp(file, kImreadMaxPixels, storedAsRead(read, flags));
}

// cv::imread's result for a binary PGM: the stored samples, read as stored or as grey (8 bits, or
// 16 when any depth is asked). A 16-bit file read as 8 bits follows OpenCV's rule: the module.
std::optional<cv::Mat> imreadOfBinaryPgm(const fs::path& file, int flags) {
  const PlainRead read = plainReadOf(flags);
  if (read == PlainRead::Other) return std::nullopt;
  return readBinaryPgm(file, kImreadMaxPixels, storedAsRead(read, flags));
}

// readImageFile's result for a plain PNG: what the module's decoder makes of it.
std::optional<ImageFileContent> frameOfPlainPng(const fs::path& file, std::uint64_t max_pixels) {
  auto png = readPlainPng(file, max_pixels);
  if (!png) return std::nullopt;
  return frameOfDecodedPixels(std::move(png->pixels));
}

// readImageFile's result for a plain JPEG: OpenImageIO in the module reads the stored components
// with the same library and settings (and applies no EXIF orientation).
std::optional<ImageFileContent> frameOfPlainJpeg(const fs::path& file, std::uint64_t max_pixels) {
  auto jpeg = readPlainJpeg(file, max_pixels, JpegOutput::Stored);
  if (!jpeg) return std::nullopt;
  return frameOfDecodedPixels(std::move(jpeg->pixels));
}

// readImageFile's result for a plain TIFF: OpenImageIO in the module reads the stored samples
// with the same library.
std::optional<ImageFileContent> frameOfPlainTiff(const fs::path& file, std::uint64_t max_pixels) {
  auto tiff = readPlainTiff(file, max_pixels);
  if (!tiff) return std::nullopt;
  return frameOfDecodedPixels(std::move(*tiff));
}

// readImageFile's result for a plain BMP: OpenImageIO in the module reads a grey palette as one
// grey channel and 24 bits as RGB, which the frame rule takes as the colour it is.
std::optional<ImageFileContent> frameOfPlainBmp(const fs::path& file, std::uint64_t max_pixels) {
  auto bmp = readPlainBmp(file, max_pixels);
  if (!bmp) return std::nullopt;
  return frameOfDecodedPixels(std::move(*bmp));
}

// readImageFile's result for a binary PGM: the module reads PNM pixels with OpenCV.
std::optional<ImageFileContent> frameOfBinaryPgm(const fs::path& file, std::uint64_t max_pixels) {
  auto pgm = readBinaryPgm(file, max_pixels);
  if (!pgm) return std::nullopt;
  return frameOfDecodedPixels(std::move(*pgm));
}

// ".png" in any case: the format cv::imwrite and cv::imencode take the name to mean.
bool isPngName(const std::string& ext) {
  static constexpr char kPng[] = ".png";
  if (ext.size() != 4) return false;
  for (std::size_t i = 0; i < 4; ++i)
    if (std::tolower(static_cast<unsigned char>(ext[i])) != kPng[i]) return false;
  return true;
}

bool writeBytes(const fs::path& file, const std::vector<unsigned char>& bytes) {
  std::ofstream out(file, std::ios::binary | std::ios::trunc);
  out.write(reinterpret_cast<const char*>(bytes.data()),
            static_cast<std::streamsize>(bytes.size()));
  return static_cast<bool>(out.flush());
}

}  // namespace

const std::string& imageCodecsProblem() {
  return loaded().problem;
}

cv::Mat readImage(const fs::path& file, int flags) {
  if (auto png = imreadOfPlainPng(file, flags)) return *png;
  if (auto jpeg = imreadOfPlainJpeg(file, flags)) return *jpeg;
  if (auto tiff = imreadOfPlainTiff(file, flags)) return *tiff;
  if (auto bmp = imreadOfPlainBmp(file, flags)) return *bmp;
  if (auto pgm = imreadOfBinaryPgm(file, flags)) return *pgm;
  const ImageCodecTable* table = loaded().table;
  return table ? table->read(file.string(), flags) : cv::Mat();
}

bool writeImage(const fs::path& file, const cv::Mat& image, const std::vector<int>& params) {
  if (params.empty() && isPngName(file.extension().string())) {
    if (auto png = encodePlainPng(image)) return writeBytes(file, *png);
  }
  const ImageCodecTable* table = loaded().table;
  return table && table->write(file.string(), image, params);
}

bool encodeImage(const std::string& ext, const cv::Mat& image, std::vector<unsigned char>& bytes,
                 const std::vector<int>& params) {
  if (params.empty() && isPngName(ext)) {
    if (auto png = encodePlainPng(image)) {
      bytes = std::move(*png);
      return true;
    }
  }
  const ImageCodecTable* table = loaded().table;
  return table && table->encode(ext, image, bytes, params);
}

cv::Mat decodeImage(const cv::Mat& bytes, int flags) {
  const ImageCodecTable* table = loaded().table;
  return table ? table->decode(bytes, flags) : cv::Mat();
}

ImageFileContent readImageFile(const fs::path& file, std::uint64_t max_pixels) {
  if (auto png = frameOfPlainPng(file, max_pixels)) return std::move(*png);
  if (auto jpeg = frameOfPlainJpeg(file, max_pixels)) return std::move(*jpeg);
  if (auto tiff = frameOfPlainTiff(file, max_pixels)) return std::move(*tiff);
  if (auto bmp = frameOfPlainBmp(file, max_pixels)) return std::move(*bmp);
  if (auto pgm = frameOfBinaryPgm(file, max_pixels)) return std::move(*pgm);
  const LoadedCodecs& codecs = loaded();
  if (codecs.table) return codecs.table->readFile(file, max_pixels);
  ImageFileContent content;
  content.error = file.string() + ": cannot read image: " + codecs.problem;
  return content;
}

}  // namespace facet
