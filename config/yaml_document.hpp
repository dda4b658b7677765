#pragma once
// Reading YAML files with their positions, and reading scalars strictly: a quoted "5" is text,
// not a number; "1.5" is not an integer. yaml-cpp counts lines and columns from 0; every
// SourceLocation here counts from 1.

#include <filesystem>
#include <optional>
#include <string>

#include <yaml-cpp/yaml.h>
#include <opencv2/core/types.hpp>

#include "config/diagnostic.hpp"

namespace facet::config {

struct YamlFile {
  YAML::Node root;
  std::string bytes;  // the file's content, for hashing
};

// Reads and parses `file`. On failure (unreadable, not YAML, empty) adds an error and returns
// nullopt; a syntax error is reported at its line and column.
std::optional<YamlFile> readYamlFile(const std::filesystem::path& file, Diagnostics& out);

// Where `node` starts in `file` (line 0 when yaml-cpp has no position for it).
SourceLocation locate(const std::filesystem::path& file, const YAML::Node& node);

// Strict scalar readers: nullopt when the node is not a plain scalar of that type.
std::optional<long long> readInteger(const YAML::Node& node);
std::optional<double> readNumber(const YAML::Node& node);
std::optional<bool> readBoolean(const YAML::Node& node);
std::optional<std::string> readString(const YAML::Node& node);  // any scalar
// [x, y]; [x, y, width, height] with width, height > 0; [low, high].
std::optional<cv::Point2d> readPoint(const YAML::Node& node);
std::optional<cv::Rect2d> readRect(const YAML::Node& node);
std::optional<std::pair<double, double>> readRange(const YAML::Node& node);

// How a node looks, for "must be a number, not <describe>" messages.
std::string describe(const YAML::Node& node);

}  // namespace facet::config
