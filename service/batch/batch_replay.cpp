#include "service/batch/batch_replay.hpp"

#include <algorithm>

#include "algorithms/scan/scan_file.hpp"
#include "camera/image_file_list.hpp"
#include "camera/image_file_reader.hpp"
#include "service/daemon/part_origin.hpp"

namespace facet::service {
namespace {

// The replay camera's image types (camera/replay_camera.cpp), so that a shard sees the same
// files as facetd --replay.
const std::vector<std::string>& imageExtensions() {
  static const std::vector<std::string> extensions = {".png", ".tif", ".tiff", ".bmp", ".pgm",
                                                      ".ppm", ".pnm", ".pbm",  ".jpg", ".jpeg"};
  return extensions;
}

constexpr std::uint64_t kMaxPixels = std::uint64_t{1} << 28;  // the replay camera's default

}  // namespace

std::vector<RecordedPart> listShare(const std::filesystem::path& folder, const std::string& glob,
                                    bool scans, const Shard& shard) {
  std::vector<std::filesystem::path> files;
  try {
    files = listRecordedFiles(folder, scans && glob.empty() ? "*.csv" : glob,
                              scans ? std::vector<std::string>{".csv"} : imageExtensions());
  } catch (const std::exception& e) {
    throw std::runtime_error(folder.string() + ": " + e.what());
  }
  std::vector<RecordedPart> share;
  for (std::size_t i = 0; i < files.size(); ++i)
    if (shard.takes(files[i])) share.push_back({files[i], i + 1});
  return share;
}

PartResult inspectRecordedPart(const PreparedRecipe& recipe, const RecordedPart& part,
                               const SidecarMetadata& sidecars, bool scan) {
  PartResult p;
  p.partId = part.partId;
  p.time = std::chrono::system_clock::now();
  Frame frame;
  frame.id = part.partId;
  frame.source = part.file.string();
  std::string sidecarError;
  frame.metadata = sidecars.forImage(part.file, &sidecarError);
  recordPartOrigin(p, &recipe.recipe(), frame);
  PartInput input;
  try {
    if (scan) {
      input.scan = scan::readScanCsvFile(part.file.string());
    } else {
      auto content = readImageFile(part.file, kMaxPixels);
      if (!content.ok()) {
        p.verdict = Verdict::Error;
        p.error = "not inspected: " + content.error;
        return p;
      }
      input.image = std::move(content.image);
    }
  } catch (const std::exception& e) {
    p.verdict = Verdict::Error;
    p.error = "not inspected: " + part.file.string() + ": " + e.what();
    return p;
  }
  recordOutcome(p, inspectPart(input, recipe));
  return p;
}

}  // namespace facet::service
