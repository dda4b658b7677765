#pragma once
// A circular window resampled on a log-polar grid: row r is the ring of radius
// radius0 * ringRatio^r, column t the angle 2 pi t / angles. A rotation of the image about the
// window centre becomes a cyclic shift along the angle axis and a scale change a shift along the
// ring axis, so NCC over shifts compares windows under any rotation and a range of scales.
//
// Samples are stored as integers (grey * 2^11, bilinear) so that every sum of the NCC is exact:
// the accelerated matchers then give bit-identical scores to plain NCC.

#include <cstdint>
#include <vector>

#include <opencv2/core.hpp>

namespace facet {

struct LogPolarParams {
  int angles = 32;          // samples per ring (angle resolution 360/angles degrees)
  int rings = 12;           // rings compared by the NCC
  int ringShifts = 2;       // extra rings on each side: scale shifts of +-ringShifts rings
  double ringRatio = 1.19;  // radius ratio of consecutive rings (2^(1/4))
  // Radius of the innermost compared ring, in units of the region scale (shape matrix).
  double innerRadius = 0.6;
};

struct LogPolarWindow {
  int angles = 0;
  int rows = 0;                       // rings + 2 * ringShifts
  std::vector<std::int16_t> samples;  // rows x angles, row-major
  // Sum tables over rows: ringSum[r] = sum of rows < r, ringSquares[r] = sum of squares.
  std::vector<std::int64_t> ringSum;
  std::vector<std::int64_t> ringSquares;
  // Column sum table: columnSum[r * angles + t] = sum of sample (t) over rows < r.
  std::vector<std::int32_t> columnSum;
  // Amplitude spectrum of each ring along the angle, frequencies 1..angles/2, weighted so that a
  // dot product of two rings gives sum_{k=1}^{angles-1} |X_k| |Y_k| (rows x angles/2, float).
  std::vector<float> ringSpectrum;
  bool valid = false;  // false when the window leaves the image
  [[nodiscard]] const std::int16_t* row(int r) const { return samples.data() + 2 * r * angles; }
};

// Octaves of `grey` (CV_32F in [0, 1]) lightly smoothed, from which windows are sampled at a
// resolution matching their size (no aliasing of large windows).
std::vector<cv::Mat> buildSamplingPyramid(const cv::Mat& grey, int octaves = 6);

// Samples the window centred at `centre` (full-resolution pixels) through `shape` (unit circle
// -> image offsets in pixels). Ring r has radius innerRadius * ringRatio^(r - ringShifts).
LogPolarWindow sampleLogPolar(const std::vector<cv::Mat>& pyramid, cv::Point2d centre,
                              const cv::Matx22d& shape, const LogPolarParams& params);

}  // namespace facet
