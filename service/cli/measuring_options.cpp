#include "service/cli/measuring_options.hpp"

#include <cmath>
#include <filesystem>
#include <sstream>
#include <vector>

#include "service/cli/command_line.hpp"

namespace facet::cli {
namespace {

std::vector<double> parseNumbers(const std::string& text, std::size_t count,
                                 const std::string& option, const std::string& shape) {
  std::vector<double> values;
  std::istringstream in(text);
  std::string item;
  while (std::getline(in, item, ',')) {
    std::size_t used = 0;
    double v = 0;
    try {
      v = std::stod(item, &used);
    } catch (const std::exception&) {
      used = 0;
    }
    if (used == 0 || item.find_first_not_of(" \t", used) != std::string::npos || !std::isfinite(v))
      throw InputError(option + " must be " + shape + " (got \"" + text + "\")");
    values.push_back(v);
  }
  if (values.size() != count || (!text.empty() && text.back() == ','))
    throw InputError(option + " must be " + shape + " (got \"" + text + "\")");
  return values;
}

}  // namespace

MeasuringRect parseMeasuringRect(const std::string& text, const std::string& option) {
  const auto v = parseNumbers(text, 5, option, "cx,cy,length,width,angle in pixels and degrees");
  return {v[0], v[1], v[2], v[3], v[4]};
}

MeasuringArc parseMeasuringArc(const std::string& text, const std::string& option) {
  const auto v =
      parseNumbers(text, 6, option, "cx,cy,radius,start,extent,width in pixels and degrees");
  if (!(v[2] > 0)) throw InputError(option + ": the radius must be positive");
  return {v[0], v[1], v[2], v[3], v[4], v[5]};
}

cv::Rect parseRegion(const std::string& text, const std::string& option) {
  const auto v = parseNumbers(text, 4, option, "x,y,w,h in whole pixels");
  for (double x : v)
    if (x != std::floor(x))
      throw InputError(option + " must be whole pixels (got \"" + text + "\")");
  return {static_cast<int>(v[0]), static_cast<int>(v[1]), static_cast<int>(v[2]),
          static_cast<int>(v[3])};
}

EdgePolarity parseEdgePolarity(const std::string& text) {
  if (text == "any") return EdgePolarity::Any;
  if (text == "rising") return EdgePolarity::Rising;
  if (text == "falling") return EdgePolarity::Falling;
  throw InputError("--polarity must be any, rising or falling (got \"" + text + "\")");
}

EdgeSelect parseEdgeSelect(const std::string& text) {
  if (text == "all") return EdgeSelect::All;
  if (text == "first") return EdgeSelect::First;
  if (text == "last") return EdgeSelect::Last;
  if (text == "strongest") return EdgeSelect::Strongest;
  throw InputError("--select must be all, first, last or strongest (got \"" + text + "\")");
}

}  // namespace facet::cli
