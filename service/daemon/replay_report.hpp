#pragma once
// The replay report: one self-contained HTML file (inline CSS and SVG, images as base64 PNG, no
// script) that shows what a recipe did over a recorded folder: the verdict of every part beside
// the verdict recorded in its sidecar, histograms and trends of every measured value against its
// tolerance band, process capability, thumbnails of the failed parts and the time per step.

#include <ostream>
#include <string>
#include <vector>

#include "service/engine/part_result.hpp"

namespace facet::service {

struct ReplayedPart {
  PartResult result;
  std::vector<unsigned char> thumbnailPng;  // overlay picture, downscaled; empty = none
};

struct ReplayReport {
  std::string title;         // e.g. the recipe's name
  std::string recipeFile;    // as given on the command line
  std::string imagesFolder;  // as given on the command line
  double mmPerPixel = 0;
  std::string generatedAt;  // ISO 8601 UTC
  std::vector<ReplayedPart> parts;
};

// Writes the HTML document.
void writeReplayReport(const ReplayReport& report, std::ostream& out);

// "pass"/"fail"/"error" differs from the sidecar's expected verdict (false without one).
bool verdictUnexpected(const PartResult& part);

}  // namespace facet::service
