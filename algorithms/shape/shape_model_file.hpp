#pragma once
// Shape model files: a versioned binary format.
//
// Layout (little-endian): magic "FACETSHM", uint32 format version, uint64 payload size, payload,
// uint64 FNV-1a checksum of the payload. A file that is truncated, has a wrong magic, an unknown
// version or a checksum mismatch is refused with ShapeModelFileError naming the file.

#include <cstdint>
#include <filesystem>
#include <stdexcept>

#include "algorithms/shape/shape_model.hpp"

namespace facet {

// Version 2 adds the model's edge estimator (one byte after the subpixel points); version 1 files
// still load, as models of the profile fit. Version 3 adds the model's near-symmetries after it
// (a count, then angle, centre x, centre y and score of each), found once when the model is made:
// finding them took 1-9 ms at every load. Files of versions 1 and 2 have them found at load.
// Version 4 adds the periods the search tracks (ShapeModel::trackedPeriods) after them (a count,
// then shift x, shift y and score of each): finding them took 2-4 ms at every load of a 4-level
// model, 38 ms of a 6-level one. Files of versions 1 to 3 have them found at load.
inline constexpr std::uint32_t kShapeModelFileVersion = 4;

struct ShapeModelFileError : std::runtime_error {
  using std::runtime_error::runtime_error;
};

// Writes `model` to `path` (overwriting it). Throws ShapeModelFileError when it cannot write.
void saveShapeModel(const ShapeModel& model, const std::filesystem::path& path);

// Reads a model written by saveShapeModel. Throws ShapeModelFileError ("<path>: <reason>") for a
// missing, truncated, corrupt or wrong-version file.
ShapeModel loadShapeModel(const std::filesystem::path& path);

}  // namespace facet
