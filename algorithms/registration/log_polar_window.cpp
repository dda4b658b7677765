#include "algorithms/registration/log_polar_window.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <vector>

#include <opencv2/imgproc.hpp>

namespace facet {
namespace {

constexpr double kSampleScale = 2048.0;  // grey [0, 1] -> integer samples (11 bits)

bool bilinear(const cv::Mat& img, double x, double y, double& value) {
  if (x < 0 || y < 0 || x > img.cols - 1.001 || y > img.rows - 1.001) return false;
  const int x0 = static_cast<int>(x), y0 = static_cast<int>(y);
  const double fx = x - x0, fy = y - y0;
  const float* r0 = img.ptr<float>(y0);
  const float* r1 = img.ptr<float>(y0 + 1);
  value =
      (1 - fy) * ((1 - fx) * r0[x0] + fx * r0[x0 + 1]) + fy * ((1 - fx) * r1[x0] + fx * r1[x0 + 1]);
  return true;
}

// For A angle samples: their cosines and sines, and the DFT's in the order each frequency k meets
// them (k * t mod A), laid out so that no ring indexes them by a division. The same for every
// window: made once per thread for the last A asked for.
struct AngleTables {
  int angles = 0;
  std::vector<double> cosines, sines;
  std::vector<double> cosinesByFrequency, sinesByFrequency;  // frequencies 1 .. A / 2, A each
};
const AngleTables& angleTables(int A) {
  thread_local AngleTables tables;
  if (tables.angles == A) return tables;
  tables.angles = A;
  tables.cosines.resize(A), tables.sines.resize(A);
  for (int t = 0; t < A; ++t) {
    tables.cosines[t] = std::cos(2.0 * std::numbers::pi * t / A);
    tables.sines[t] = std::sin(2.0 * std::numbers::pi * t / A);
  }
  const int K = A / 2;
  tables.cosinesByFrequency.resize(static_cast<std::size_t>(K) * A);
  tables.sinesByFrequency.resize(static_cast<std::size_t>(K) * A);
  for (int k = 1; k <= K; ++k)
    for (int t = 0; t < A; ++t) {
      const int phase = (k * t) % A;
      tables.cosinesByFrequency[static_cast<std::size_t>(k - 1) * A + t] = tables.cosines[phase];
      tables.sinesByFrequency[static_cast<std::size_t>(k - 1) * A + t] = tables.sines[phase];
    }
  return tables;
}

}  // namespace

std::vector<cv::Mat> buildSamplingPyramid(const cv::Mat& grey, int octaves) {
  CV_Assert(grey.type() == CV_32F);
  std::vector<cv::Mat> pyramid;
  cv::Mat level;
  cv::GaussianBlur(grey, level, cv::Size(), 0.8, 0.8, cv::BORDER_REFLECT);
  pyramid.push_back(level);
  for (int o = 1; o < octaves && std::min(level.rows, level.cols) >= 16; ++o) {
    cv::Mat next;
    cv::pyrDown(level, next);
    pyramid.push_back(next);
    level = next;
  }
  return pyramid;
}

LogPolarWindow sampleLogPolar(const std::vector<cv::Mat>& pyramid, cv::Point2d centre,
                              const cv::Matx22d& shape, const LogPolarParams& p) {
  LogPolarWindow w;
  w.angles = p.angles;
  w.rows = p.rings + 2 * p.ringShifts;
  const int A = w.angles;
  // Sample from the octave where one unit of the region spans about two pixels or more.
  const double unit = std::sqrt(std::abs(cv::determinant(shape)));
  int octave = unit > 0 ? static_cast<int>(std::floor(std::log2(unit / 2.0))) : 0;
  octave = std::clamp(octave, 0, static_cast<int>(pyramid.size()) - 1);
  const cv::Mat& img = pyramid[octave];
  const double inv = std::ldexp(1.0, -octave);

  const AngleTables& tables = angleTables(A);
  const std::vector<double>&cosines = tables.cosines, &sines = tables.sines;
  w.samples.assign(static_cast<std::size_t>(w.rows) * 2 * A, 0);
  for (int r = 0; r < w.rows; ++r) {
    const double rho = p.innerRadius * std::pow(p.ringRatio, r - p.ringShifts);
    std::int16_t* row = w.samples.data() + 2 * r * A;
    for (int t = 0; t < A; ++t) {
      const double ux = rho * cosines[t], uy = rho * sines[t];
      const double x = (centre.x + shape(0, 0) * ux + shape(0, 1) * uy) * inv;
      const double y = (centre.y + shape(1, 0) * ux + shape(1, 1) * uy) * inv;
      double v = 0;
      if (!bilinear(img, x, y, v)) return w;  // leaves the image: invalid
      const auto q = static_cast<std::int16_t>(std::lround(std::clamp(v, 0.0, 1.0) * kSampleScale));
      row[t] = q;
      row[t + A] = q;
    }
  }
  w.ringSum.assign(w.rows + 1, 0);
  w.ringSquares.assign(w.rows + 1, 0);
  w.columnSum.assign(static_cast<std::size_t>(w.rows + 1) * A, 0);
  for (int r = 0; r < w.rows; ++r) {
    const std::int16_t* row = w.row(r);
    std::int64_t s = 0, s2 = 0;
    for (int t = 0; t < A; ++t) {
      s += row[t];
      s2 += static_cast<std::int64_t>(row[t]) * row[t];
      w.columnSum[(r + 1) * A + t] = w.columnSum[r * A + t] + row[t];
    }
    w.ringSum[r + 1] = w.ringSum[r] + s;
    w.ringSquares[r + 1] = w.ringSquares[r] + s2;
  }
  const int K = A / 2;
  w.ringSpectrum.assign(static_cast<std::size_t>(w.rows) * K, 0.f);
  for (int r = 0; r < w.rows; ++r) {
    const std::int16_t* row = w.row(r);
    for (int k = 1; k <= K; ++k) {
      const double* cosK = tables.cosinesByFrequency.data() + static_cast<std::size_t>(k - 1) * A;
      const double* sinK = tables.sinesByFrequency.data() + static_cast<std::size_t>(k - 1) * A;
      double re = 0, im = 0;
      for (int t = 0; t < A; ++t) {
        re += row[t] * cosK[t];
        im -= row[t] * sinK[t];
      }
      const double weight = (2 * k == A) ? 1.0 : std::sqrt(2.0);
      w.ringSpectrum[r * K + k - 1] = static_cast<float>(weight * std::hypot(re, im));
    }
  }
  w.valid = true;
  return w;
}

}  // namespace facet
