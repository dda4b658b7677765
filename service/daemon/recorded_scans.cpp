#include "service/daemon/recorded_scans.hpp"

#include <filesystem>

#include <spdlog/spdlog.h>

#include "algorithms/scan/scan_file.hpp"
#include "camera/sidecar_metadata.hpp"

namespace facet::service {

Frame recordedScanFrame(const RangeScan& scan) {
  Frame frame;
  frame.id = scan.id;
  frame.source = scan.source;
  frame.metadata = scan.metadata;
  // CARMEN scans are named "file:line"; CSV scans by their file.
  std::string source = scan.source;
  if (const auto colon = source.rfind(':');
      colon != std::string::npos && colon + 1 < source.size() &&
      source.find_first_not_of("0123456789", colon + 1) == std::string::npos)
    source.resize(colon);
  const std::filesystem::path file = source;
  try {
    for (auto& [key, value] : SidecarMetadata::loadFolder(file.parent_path()).forImage(file))
      frame.metadata.emplace(key, value);
  } catch (const std::exception& e) {
    spdlog::warn("{}: {}", file.string(), e.what());
  }
  return frame;
}

std::optional<scan::Scan> scanOfFrame(const Frame& frame, std::uint64_t partId) {
  const auto it = frame.metadata.find("scan");
  if (it == frame.metadata.end()) return std::nullopt;
  const auto path = std::filesystem::path(frame.source).parent_path() / it->second;
  try {
    return scan::readScanCsvFile(path.string());
  } catch (const std::exception& e) {
    spdlog::error("part {}: scan {}: {}", partId, path.string(), e.what());
    return std::nullopt;
  }
}

}  // namespace facet::service
