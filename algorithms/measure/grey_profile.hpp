#pragma once
// The grey profile along a measuring path: the mean grey value across the path's width at
// evenly spaced positions along its axis.
//
// Why sampled rather than binned pixels: a rectangle at any angle reads the image through
// bilinear interpolation at points spaced `step` along and `crossStep` across the axis, so every
// angle gets the same averaging and no pixel is lost to rounding the rectangle onto the grid.
// Bilinear interpolation keeps the integral of a profile (the trapezoid rule of its samples),
// which is what the edge estimator relies on (profile_edges.hpp).

#include <vector>

#include <opencv2/core.hpp>

#include "algorithms/measure/measuring_path.hpp"

namespace facet {

struct GreyProfileParams {
  double step = 0.25;      // pixels between samples along the axis
  double crossStep = 0.5;  // pixels between the averaged lines across the axis
};

struct GreyProfile {
  // values[i] is the mean grey (8-bit scale; 16-bit images divided by 256) at axis position
  // start + i * step. Only the longest run of positions inside the image is kept.
  std::vector<double> values;
  double start = 0;
  double step = 0;
  // Part of the path lay outside the image: the profile covers only what was inside.
  bool partial = false;
  // The sensor's largest value on the values' scale (255; 65535 / 256 for 16 bits): a value
  // there, or at 0, averages pixels the sensor clipped.
  double clipLevel = 255.0;

  [[nodiscard]] double positionAt(double index) const { return start + index * step; }
  // Whether samples first..last hold one the sensor clipped: at clipLevel or at 0, up to the
  // rounding of the bilinear weights' sum.
  [[nodiscard]] bool clippedWithin(int first, int last) const {
    constexpr double kRounding = 1e-6;
    for (int i = first; i <= last; ++i)
      if (values[i] >= clipLevel - kRounding || values[i] <= kRounding) return true;
    return false;
  }
  [[nodiscard]] double end() const {
    return start + static_cast<double>(values.empty() ? 0 : values.size() - 1) * step;
  }
};

// Samples `image` (CV_8UC1 or CV_16UC1) along `path`. A position counts as inside when at least
// half of its cross samples fall inside the image (their mean is then taken over those inside).
// Returns an empty profile when the path is wholly outside or has no length.
GreyProfile sampleGreyProfile(const cv::Mat& image, const MeasuringPath& path,
                              const GreyProfileParams& params = {});

// The same sampling for many paths (a line's cross calipers), its buffers kept between them.
class GreyProfileSampler {
 public:
  explicit GreyProfileSampler(const GreyProfileParams& params = {});

  // As sampleGreyProfile(image, path, params); the profile lives until the next call.
  const GreyProfile& sample(const cv::Mat& image, const MeasuringPath& path);

 private:
  template <class T>
  void sampleAs(const cv::Mat& image, const MeasuringPath& path, double scale);

  GreyProfileParams params_;
  GreyProfile profile_;
  std::vector<double> offsets_;               // cross offsets of the averaged lines
  std::vector<cv::Point2d> origin_, across_;  // per position: the axis point, the cross direction
  std::vector<double> sums_;                  // per position: the sum over its cross samples
  std::vector<int> counts_;                   // per position: how many of them lay inside
};

}  // namespace facet
