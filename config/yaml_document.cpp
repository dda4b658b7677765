#include "config/yaml_document.hpp"

#include <charconv>
#include <cmath>
#include <fstream>
#include <sstream>

namespace facet::config {
namespace {

bool isPlainScalar(const YAML::Node& node) {
  // yaml-cpp tags quoted scalars with "!": the user meant text. A missing key gives an invalid
  // node, on which every query but operator bool throws.
  return node && node.IsScalar() && node.Tag() != "!";
}

}  // namespace

std::optional<YamlFile> readYamlFile(const std::filesystem::path& file, Diagnostics& out) {
  std::ifstream in(file, std::ios::binary);
  if (!in) {
    out.error({file}, "cannot read the file");
    return std::nullopt;
  }
  std::ostringstream buffer;
  buffer << in.rdbuf();
  YamlFile result{{}, buffer.str()};
  try {
    result.root = YAML::Load(result.bytes);
  } catch (const YAML::Exception& e) {
    SourceLocation where{file};
    if (!e.mark.is_null()) where = {file, e.mark.line + 1, e.mark.column + 1};
    out.error(where, "not valid YAML: " + e.msg);
    return std::nullopt;
  }
  if (!result.root.IsDefined() || result.root.IsNull()) {
    out.error({file, 1, 1}, "the file is empty");
    return std::nullopt;
  }
  return result;
}

SourceLocation locate(const std::filesystem::path& file, const YAML::Node& node) {
  if (!node) return {file};
  const YAML::Mark mark = node.Mark();
  if (mark.is_null() || mark.line < 0) return {file};
  return {file, mark.line + 1, mark.column + 1};
}

std::optional<long long> readInteger(const YAML::Node& node) {
  if (!isPlainScalar(node)) return std::nullopt;
  const std::string& s = node.Scalar();
  const char* begin = s.data() + (s.starts_with('+') ? 1 : 0);
  long long value = 0;
  const auto [end, ec] = std::from_chars(begin, s.data() + s.size(), value);
  if (ec != std::errc{} || end != s.data() + s.size()) return std::nullopt;
  return value;
}

std::optional<double> readNumber(const YAML::Node& node) {
  if (!isPlainScalar(node)) return std::nullopt;
  const std::string& s = node.Scalar();
  const char* begin = s.data() + (s.starts_with('+') ? 1 : 0);
  double value = 0;
  const auto [end, ec] = std::from_chars(begin, s.data() + s.size(), value);
  if (ec != std::errc{} || end != s.data() + s.size() || !std::isfinite(value)) return std::nullopt;
  return value;
}

std::optional<bool> readBoolean(const YAML::Node& node) {
  if (!isPlainScalar(node)) return std::nullopt;
  const std::string& s = node.Scalar();
  if (s == "true" || s == "True" || s == "TRUE") return true;
  if (s == "false" || s == "False" || s == "FALSE") return false;
  return std::nullopt;
}

std::optional<cv::Point2d> readPoint(const YAML::Node& node) {
  if (!node || !node.IsSequence() || node.size() != 2) return std::nullopt;
  const auto x = readNumber(node[0]), y = readNumber(node[1]);
  if (!x || !y) return std::nullopt;
  return cv::Point2d(*x, *y);
}

std::optional<cv::Rect2d> readRect(const YAML::Node& node) {
  if (!node || !node.IsSequence() || node.size() != 4) return std::nullopt;
  double v[4];
  for (std::size_t i = 0; i < 4; ++i) {
    const auto x = readNumber(node[i]);
    if (!x) return std::nullopt;
    v[i] = *x;
  }
  if (v[2] <= 0 || v[3] <= 0) return std::nullopt;
  return cv::Rect2d(v[0], v[1], v[2], v[3]);
}

std::optional<std::pair<double, double>> readRange(const YAML::Node& node) {
  if (!node || !node.IsSequence() || node.size() != 2) return std::nullopt;
  const auto low = readNumber(node[0]), high = readNumber(node[1]);
  if (!low || !high) return std::nullopt;
  return std::pair{*low, *high};
}

std::optional<std::string> readString(const YAML::Node& node) {
  if (!node || !node.IsScalar()) return std::nullopt;
  return node.Scalar();
}

std::string describe(const YAML::Node& node) {
  if (!node || node.IsNull()) return "an empty value";
  if (node.IsSequence()) return "a list";
  if (node.IsMap()) return "a mapping";
  return "\"" + node.Scalar() + "\"";
}

}  // namespace facet::config
