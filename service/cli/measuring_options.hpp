#pragma once
// Parsing of the options the measuring commands (caliper, line, blob) share: placement
// rectangles, arcs and regions given as comma-separated numbers, edge polarity and selection,
// and reading the image. Each error names the option and what it got.

#include <string>

#include <opencv2/core.hpp>

#include "algorithms/measure/caliper.hpp"

namespace facet::cli {

// "cx,cy,length,width,angle" (pixels, degrees).
MeasuringRect parseMeasuringRect(const std::string& text, const std::string& option);
// "cx,cy,radius,start,extent,width" (pixels, degrees).
MeasuringArc parseMeasuringArc(const std::string& text, const std::string& option);
// "x,y,w,h" (pixels).
cv::Rect parseRegion(const std::string& text, const std::string& option);
EdgePolarity parseEdgePolarity(const std::string& text);
EdgeSelect parseEdgeSelect(const std::string& text);

}  // namespace facet::cli
