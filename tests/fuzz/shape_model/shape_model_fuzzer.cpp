// libFuzzer target: the shape model file loader (algorithms/shape/shape_model_file.hpp).
// The file's FNV-1a checksum would stop nearly every mutation at "checksum mismatch", so inputs
// whose first byte is odd are taken as a payload and wrapped in a valid header and checksum
// (reaching the payload parser), of the current version or, with the byte's second bit set, of
// version 2 (whose payload ends before the symmetries); even ones are written as they are
// (testing the header checks).
// Expected outcome for bad input: ShapeModelFileError. A model that loads must be usable: it is
// searched for in a small image, which must end (libFuzzer's -timeout) without a sanitizer report.

#include <array>
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <vector>

#include <opencv2/core.hpp>
#include <opencv2/imgproc.hpp>

#include "algorithms/shape/find_shape_model.hpp"
#include "algorithms/shape/shape_model_file.hpp"
#include "tests/fuzz/fuzz_input_file.hpp"

namespace {

std::uint64_t fnv1a(const std::uint8_t* data, std::size_t size) {
  std::uint64_t h = 14695981039346656037ull;
  for (std::size_t i = 0; i < size; ++i) {
    h ^= data[i];
    h *= 1099511628211ull;
  }
  return h;
}

template <typename T>
void append(std::vector<std::uint8_t>& bytes, T value) {
  const auto* p = reinterpret_cast<const std::uint8_t*>(&value);
  bytes.insert(bytes.end(), p, p + sizeof(T));
}

std::vector<std::uint8_t> wrapPayload(const std::uint8_t* payload, std::size_t size,
                                      std::uint32_t version) {
  constexpr std::array<char, 8> kMagic = {'F', 'A', 'C', 'E', 'T', 'S', 'H', 'M'};
  std::vector<std::uint8_t> file(kMagic.begin(), kMagic.end());
  append<std::uint32_t>(file, version);
  append<std::uint64_t>(file, size);
  file.insert(file.end(), payload, payload + size);
  append<std::uint64_t>(file, fnv1a(payload, size));
  return file;
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  static const facet::fuzz::FuzzInputFolder folder;
  std::filesystem::path file;
  if (size > 0 && (data[0] & 1u)) {
    const auto wrapped =
        wrapPayload(data + 1, size - 1, (data[0] & 2u) ? 2u : facet::kShapeModelFileVersion);
    file = folder.write("model.fsm", wrapped.data(), wrapped.size());
  } else {
    file = folder.write("model.fsm", data, size);
  }
  try {
    const facet::ShapeModel model = facet::loadShapeModel(file);
    if (model.empty() || model.levels.empty() || model.finePoints.empty()) std::abort();
    static const cv::Mat image = [] {
      cv::Mat m(40, 48, CV_8UC1, cv::Scalar(30));
      cv::rectangle(m, {12, 10}, {34, 28}, cv::Scalar(220), cv::FILLED);
      return m;
    }();
    // A valid but very fine model (one level, tiny angle step) is slow by design: the search
    // visits every angle at every position. Only models of bounded top-level work are searched,
    // so that a timeout means a hang, not a legitimately expensive model.
    const auto& top = model.levels.back();
    const double scales =
        top.scaleStep > 0.0 ? (model.scaleMax - model.scaleMin) / top.scaleStep + 1.0 : 1.0;
    const double work = (model.angleExtent / top.angleStep + 1.0) * scales * top.points.size();
    const double border = model.radius() * model.scaleMax;  // the search pads the image by this
    if (work <= 2e5 && border <= 2000.0) {
      facet::FindParams params;
      params.minScore = 0.3;
      (void)facet::findShapeModel(image, model, params);
    }
  } catch (const facet::ShapeModelFileError&) {
  }
  return 0;
}
