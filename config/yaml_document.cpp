#include "config/yaml_document.hpp"

#include <algorithm>
#include <cctype>
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

// A quoted scalar runs to its closing quote; yaml-cpp accepts a missing one and swallows the rest
// of the file into the string ("name: \"broken" then gives "missing key 'steps'"), or closes it
// at the next value's opening quote. Where the quote opened at `begin` in `bytes` either runs to
// the end of the file or swallows a line that reads like a key or a list item, returns the
// message; nullopt when the quote is closed properly.
std::optional<std::string> unterminatedQuote(const std::string& bytes, std::size_t begin) {
  const char quote = bytes[begin];
  std::size_t end = std::string::npos;
  for (std::size_t i = begin + 1; i < bytes.size(); ++i) {
    if (quote == '"' && bytes[i] == '\\') {
      ++i;
    } else if (bytes[i] == quote) {
      if (quote == '\'' && i + 1 < bytes.size() && bytes[i + 1] == '\'') {
        ++i;  // '' is a quote inside single quotes
        continue;
      }
      end = i;
      break;
    }
  }
  const std::string missing =
      std::string("unterminated quoted text: the closing ") + quote + " is missing";
  if (end == std::string::npos) return missing;
  // Inside the quotes, a line that looks like a snake_case "key:" or "- item" was meant as YAML,
  // not text.
  const auto lineAt = [&](std::size_t i) {
    return std::to_string(std::count(bytes.begin(), bytes.begin() + static_cast<long>(i), '\n') +
                          1);
  };
  for (std::size_t nl = bytes.find('\n', begin); nl < end; nl = bytes.find('\n', nl + 1)) {
    std::size_t i = nl + 1;
    while (i < end && (bytes[i] == ' ' || bytes[i] == '\t')) ++i;
    if (i + 1 < end && bytes[i] == '-' && bytes[i + 1] == ' ')
      return missing + " (the text runs on over the list item on line " + lineAt(i) + ")";
    std::size_t k = i;
    const auto keyChar = [](char c) {
      return (c >= 'a' && c <= 'z') || (c >= '0' && c <= '9') || c == '_';
    };
    while (k < end && keyChar(bytes[k])) ++k;
    if (k > i && bytes[i] >= 'a' && bytes[i] <= 'z' && k + 1 < end && bytes[k] == ':' &&
        (bytes[k + 1] == ' ' || bytes[k + 1] == '\n'))
      return missing + " (the text runs on over the key on line " + lineAt(i) + ")";
  }
  return std::nullopt;
}

// A quoted value that opens on a line up to `lastLine` (1-based) and runs on: the syntax error
// yaml-cpp reports further down ("end of map not found") is its consequence, so this is the
// error to report.
std::optional<SourceLocation> openQuoteUpTo(const std::string& bytes, int lastLine,
                                            const std::filesystem::path& file,
                                            std::string& message) {
  const auto keyChar = [](char c) {
    return std::isalnum(static_cast<unsigned char>(c)) || c == '_';
  };
  std::size_t start = 0;
  for (int line = 1; start < bytes.size() && line <= lastLine; ++line) {
    const std::size_t end = std::min(bytes.find('\n', start), bytes.size());
    std::size_t i = start;
    const auto skipSpaces = [&] {
      while (i < end && bytes[i] == ' ') ++i;
    };
    skipSpaces();
    if (i + 1 < end && bytes[i] == '-' && bytes[i + 1] == ' ') i += 2, skipSpaces();
    std::size_t k = i;
    while (k < end && keyChar(bytes[k])) ++k;
    if (k > i && k < end && bytes[k] == ':') i = k + 1, skipSpaces();
    if (i < end && (bytes[i] == '"' || bytes[i] == '\'')) {
      if (auto problem = unterminatedQuote(bytes, i)) {
        message = *problem;
        return SourceLocation{file, line, static_cast<int>(i - start) + 1};
      }
    }
    start = end + 1;
  }
  return std::nullopt;
}

// The first quoted scalar (key or value) of the document whose quote is not closed properly.
std::optional<SourceLocation> findUnterminatedQuote(const YAML::Node& node,
                                                    const std::string& bytes,
                                                    const std::filesystem::path& file,
                                                    std::string& message) {
  if (!node) return std::nullopt;
  if (node.IsScalar()) {
    const YAML::Mark mark = node.Mark();
    if (node.Tag() != "!" || mark.is_null() || mark.pos < 0 ||
        static_cast<std::size_t>(mark.pos) >= bytes.size())
      return std::nullopt;
    const char c = bytes[static_cast<std::size_t>(mark.pos)];
    if (c != '"' && c != '\'') return std::nullopt;
    if (auto problem = unterminatedQuote(bytes, static_cast<std::size_t>(mark.pos))) {
      message = *problem;
      return SourceLocation{file, mark.line + 1, mark.column + 1};
    }
    return std::nullopt;
  }
  for (auto it = node.begin(); it != node.end(); ++it) {
    if (node.IsMap()) {
      if (auto where = findUnterminatedQuote(it->first, bytes, file, message)) return where;
      if (auto where = findUnterminatedQuote(it->second, bytes, file, message)) return where;
    } else if (auto where = findUnterminatedQuote(*it, bytes, file, message)) {
      return where;
    }
  }
  return std::nullopt;
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
    std::string message;
    if (const auto quote =
            openQuoteUpTo(result.bytes, where.line > 0 ? where.line : 1 << 30, file, message))
      out.error(*quote, "not valid YAML: " + message);
    else
      out.error(where, "not valid YAML: " + e.msg);
    return std::nullopt;
  }
  if (!result.root.IsDefined() || result.root.IsNull()) {
    out.error({file, 1, 1}, "the file is empty");
    return std::nullopt;
  }
  std::string message;
  if (const auto where = findUnterminatedQuote(result.root, result.bytes, file, message)) {
    out.error(*where, "not valid YAML: " + message);
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
