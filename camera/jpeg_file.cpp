#include "camera/jpeg_file.hpp"

#include <csetjmp>
#include <cstdio>
#include <memory>

// jpeglib.h needs FILE and size_t declared before it.
#include <jpeglib.h>

#include <opencv2/imgproc.hpp>

#include "camera/exif_orientation.hpp"

namespace facet {
namespace {

// libjpeg reports errors through error_exit, which must not return: it jumps back to the
// setjmp in readInto. The functions between hold nothing with a destructor, so a jump skips no
// C++ cleanup. Warnings (corrupt data the library decodes anyway) are remembered: such a file is
// left to the module, which prints them as cv::imread does.
struct ErrorManager {
  jpeg_error_mgr pub{};
  std::jmp_buf jump{};
  bool warned = false;
};

[[noreturn]] void onError(j_common_ptr cinfo) {
  std::longjmp(reinterpret_cast<ErrorManager*>(cinfo->err)->jump, 1);
}

void onMessage(j_common_ptr cinfo, int level) {
  if (level < 0) reinterpret_cast<ErrorManager*>(cinfo->err)->warned = true;
}

struct Decompressor {
  jpeg_decompress_struct cinfo{};
  ErrorManager errors;
  bool created = false;
  ~Decompressor() {
    if (created) jpeg_destroy_decompress(&cinfo);
  }
};

// OpenCV reads the Exif block from the first APP1 segment, whatever it holds.
std::optional<int> orientationOf(const jpeg_decompress_struct& cinfo) {
  for (jpeg_saved_marker_ptr m = cinfo.marker_list; m; m = m->next)
    if (m->marker == JPEG_APP0 + 1) return exifOrientation(m->data, m->data_length);
  return 1;
}

// The decode itself, between setjmp and the last libjpeg call; false on any error.
bool readInto(Decompressor& d, FILE* in, std::uint64_t maxPixels, JpegOutput output,
              PlainJpeg& out) {
  jpeg_decompress_struct& cinfo = d.cinfo;
  if (setjmp(d.errors.jump)) return false;
  jpeg_create_decompress(&cinfo);
  d.created = true;
  jpeg_stdio_src(&cinfo, in);
  jpeg_save_markers(&cinfo, JPEG_APP0 + 1, 0xffff);
  jpeg_read_header(&cinfo, TRUE);
  out.orientation = orientationOf(cinfo);  // saved markers live until the decompression ends
  const int components = cinfo.num_components;
  if (components != 1 && components != 3) return false;  // CMYK and others: the module
  // A Motion-JPEG frame leaves the Huffman tables out; OpenCV fills in the standard ones.
  if (!cinfo.ac_huff_tbl_ptrs[0] && !cinfo.ac_huff_tbl_ptrs[1] && !cinfo.dc_huff_tbl_ptrs[0] &&
      !cinfo.dc_huff_tbl_ptrs[1])
    return false;
  if (cinfo.image_width == 0 || cinfo.image_height == 0 ||
      std::uint64_t{cinfo.image_width} * cinfo.image_height > maxPixels)
    return false;
  // The settings of OpenCV's reader: grey through libjpeg's own conversion, colour as RGB (its
  // rows are then put in BGR order); everything else at the library's defaults.
  const bool grey = output == JpegOutput::Grey || components == 1;
  cinfo.out_color_space = grey ? JCS_GRAYSCALE : JCS_RGB;
  jpeg_start_decompress(&cinfo);
  out.pixels.create(static_cast<int>(cinfo.output_height), static_cast<int>(cinfo.output_width),
                    grey ? CV_8UC1 : CV_8UC3);
  while (cinfo.output_scanline < cinfo.output_height) {
    JSAMPROW row = out.pixels.ptr<unsigned char>(static_cast<int>(cinfo.output_scanline));
    jpeg_read_scanlines(&cinfo, &row, 1);
  }
  jpeg_finish_decompress(&cinfo);
  return !d.errors.warned;
}

}  // namespace

std::optional<PlainJpeg> readPlainJpeg(const std::filesystem::path& file, std::uint64_t maxPixels,
                                       JpegOutput output) {
  const std::unique_ptr<FILE, int (*)(FILE*)> in(std::fopen(file.c_str(), "rb"), &std::fclose);
  if (!in) return std::nullopt;
  unsigned char signature[3];
  if (std::fread(signature, 1, sizeof signature, in.get()) != sizeof signature ||
      signature[0] != 0xFF || signature[1] != 0xD8 || signature[2] != 0xFF)
    return std::nullopt;
  std::rewind(in.get());

  Decompressor d;
  d.cinfo.err = jpeg_std_error(&d.errors.pub);
  d.errors.pub.error_exit = onError;
  d.errors.pub.emit_message = onMessage;
  PlainJpeg out;
  if (!readInto(d, in.get(), maxPixels, output, out)) return std::nullopt;
  if (out.pixels.channels() == 3) cv::cvtColor(out.pixels, out.pixels, cv::COLOR_RGB2BGR);
  return out;
}

}  // namespace facet
