#pragma once
// Benchmark scenes for the measuring tools, each with its exact ground truth: a straight edge
// under a caliper, a bar (edge pair) under a caliper, a long straight edge under a line
// rectangle, and a frame of discs for blob analysis. Random angles and subpixel places; both
// blur models (lens_scene.hpp).

#include <cstdint>
#include <vector>

#include <opencv2/core.hpp>

#include "algorithms/measure/measuring_path.hpp"

namespace facet::bench {

enum class BlurModel { PixelGrid, Lens };
const char* blurModelName(BlurModel model);

struct SceneNoise {
  double blur = 0.9;   // Gaussian PSF sigma, pixels
  double noise = 2.0;  // grey levels
};

struct EdgeScene {
  cv::Mat image;
  MeasuringRect rect;   // the caliper
  double position = 0;  // true signed position of the edge along the axis
  bool rising = true;
  double contrast = 0;  // grey levels between the two sides
};
EdgeScene makeEdgeScene(std::uint64_t seed, BlurModel model, SceneNoise n = {});

struct BarScene {
  cv::Mat image;
  MeasuringRect rect;
  double width = 0;   // true width along the axis
  double centre = 0;  // true signed position of the bar's middle
  bool light = true;  // light bar on dark ground: rising edge first
};
BarScene makeBarScene(std::uint64_t seed, double barWidth, BlurModel model, SceneNoise n = {});

// Light (or dark) teeth of a comb across a caliper 48 px long: `teeth` bars of barWidth..+1 px,
// gaps of gapWidth..+1 px, the same grey, subpixel places, tilted up to 5 degrees.
struct CombScene {
  cv::Mat image;
  MeasuringRect rect;
  std::vector<double> widths;   // true widths along the axis, in axis order
  std::vector<double> centres;  // true signed positions of the teeth's middles
  bool light = true;            // light teeth on dark ground: rising edge first
};
CombScene makeCombScene(std::uint64_t seed, int teeth, double barWidth, double gapWidth,
                        BlurModel model, SceneNoise n = {});

struct LineScene {
  cv::Mat image;
  MeasuringRect rect;            // along the line
  cv::Point2d point, direction;  // the true line (direction along rect's axis)
  double angleDeg = 0;           // true angle, as the tool reports it
};
LineScene makeLineScene(std::uint64_t seed, BlurModel model, SceneNoise n = {});

struct BlobScene {
  cv::Mat image;
  std::vector<cv::Point2d> centres;
  std::vector<double> radii;
};
BlobScene makeBlobScene(std::uint64_t seed, BlurModel model, SceneNoise n = {},
                        cv::Size size = {1280, 1024}, int discs = 24);

}  // namespace facet::bench
