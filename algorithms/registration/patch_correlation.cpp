#include "algorithms/registration/patch_correlation.hpp"

#include <cmath>
#include <cstring>
#include <vector>

#include <opencv2/imgproc.hpp>

namespace facet {
namespace {

using Lanes = float __attribute__((vector_size(16)));
// Shifts correlated at once: five lanes of four, whose sums stay in registers.
constexpr int kBlockLanes = 5;
constexpr int kBlockShifts = 4 * kBlockLanes;

}  // namespace

void correlatePatch(const cv::Mat& image, const cv::Mat& patch, cv::Mat& result) {
  CV_Assert(image.type() == CV_32F && patch.type() == CV_32F);
  CV_Assert(image.rows >= patch.rows && image.cols >= patch.cols && !patch.empty());
  const int h = patch.rows, w = patch.cols;
  const int rows = image.rows - h + 1, cols = image.cols - w + 1;
  const double n = static_cast<double>(h) * w;

  // The patch minus its mean: the window's mean then drops out of the numerator.
  const double mean = cv::mean(patch)[0];
  std::vector<float> centred(static_cast<std::size_t>(h) * w);
  double patchEnergy = 0.0;
  for (int v = 0; v < h; ++v)
    for (int u = 0; u < w; ++u) {
      const double d = patch.at<float>(v, u) - mean;
      centred[static_cast<std::size_t>(v) * w + u] = static_cast<float>(d);
      patchEnergy += d * d;
    }
  cv::Mat sums, squares;
  cv::integral(image, sums, squares, CV_64F, CV_64F);

  // The image with zeros to the right, so that every block of shifts reads whole lanes.
  const int blocks = (cols + kBlockShifts - 1) / kBlockShifts;
  cv::Mat padded(image.rows, blocks * kBlockShifts + w, CV_32F, cv::Scalar(0));
  image.copyTo(padded(cv::Rect(0, 0, image.cols, image.rows)));

  result.create(rows, cols, CV_32F);
  std::vector<float> dot(static_cast<std::size_t>(blocks) * kBlockShifts);
  for (int y = 0; y < rows; ++y) {
    // kBlockShifts shifts of this row at once, their sums kept in registers over the whole patch.
    for (int b = 0; b < blocks; ++b) {
      Lanes acc[kBlockLanes] = {};
      for (int v = 0; v < h; ++v) {
        const float* src = padded.ptr<float>(y + v) + b * kBlockShifts;
        const float* weights = centred.data() + static_cast<std::size_t>(v) * w;
        for (int u = 0; u < w; ++u) {
          const Lanes c = {weights[u], weights[u], weights[u], weights[u]};
          for (int k = 0; k < kBlockLanes; ++k) {
            Lanes pixels;
            std::memcpy(&pixels, src + u + 4 * k, sizeof pixels);
            acc[k] += c * pixels;
          }
        }
      }
      std::memcpy(dot.data() + b * kBlockShifts, acc, sizeof acc);
    }
    const double* s0 = sums.ptr<double>(y);
    const double* s1 = sums.ptr<double>(y + h);
    const double* q0 = squares.ptr<double>(y);
    const double* q1 = squares.ptr<double>(y + h);
    float* out = result.ptr<float>(y);
    for (int x = 0; x < cols; ++x) {
      const double sum = s1[x + w] - s1[x] - s0[x + w] + s0[x];
      const double sumSquares = q1[x + w] - q1[x] - q0[x + w] + q0[x];
      const double denominator = std::sqrt(std::max(sumSquares - sum * sum / n, 0.0) * patchEnergy);
      const double numerator = dot[x];
      // As TM_CCOEFF_NORMED: a quotient rounding just past +-1 is +-1, a flat window or patch 0.
      double r = 0.0;
      if (std::abs(numerator) < denominator)
        r = numerator / denominator;
      else if (std::abs(numerator) < 1.125 * denominator)
        r = numerator > 0 ? 1.0 : -1.0;
      out[x] = static_cast<float>(r);
    }
  }
}

}  // namespace facet
