#include "algorithms/edges/edge_profile_fit.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <numbers>

namespace facet {
namespace {

// Standard normal CDF and PDF, tabulated on [-kRange, kRange] with linear interpolation
// (step 1/64: interpolation error below 1e-5).
constexpr float kRange = 6.0f;
constexpr int kPerUnit = 64;
constexpr int kTableSize = static_cast<int>(2 * kRange * kPerUnit) + 2;

struct NormalTable {
  std::array<float, kTableSize> cdf{}, pdf{};
  NormalTable() {
    for (int i = 0; i < kTableSize; ++i) {
      const double z = -kRange + static_cast<double>(i) / kPerUnit;
      cdf[i] = static_cast<float>(0.5 * std::erfc(-z / std::numbers::sqrt2));
      pdf[i] = static_cast<float>(std::exp(-0.5 * z * z) / std::sqrt(2 * std::numbers::pi));
    }
  }
  void lookup(float z, float& c, float& p) const {
    const float f = std::clamp((z + kRange) * kPerUnit, 0.0f, kTableSize - 1.001f);
    const int i = static_cast<int>(f);
    const float r = f - static_cast<float>(i);
    c = cdf[i] + r * (cdf[i + 1] - cdf[i]);
    p = pdf[i] + r * (pdf[i + 1] - pdf[i]);
  }
};

const NormalTable& normalTable() {
  static const NormalTable table;
  return table;
}

constexpr int kCapacity = 512;

struct Samples {
  int count = 0;
  float mean = 0;
  std::array<float, kCapacity> s, t, v;  // across, along, grey value minus mean
};

// Solves the symmetric positive definite n x n system A x = y by Cholesky; false if singular.
template <int N>
bool solveSpd(std::array<std::array<double, N>, N>& a, std::array<double, N>& y) {
  for (int j = 0; j < N; ++j) {
    double d = a[j][j];
    for (int k = 0; k < j; ++k) d -= a[j][k] * a[j][k];
    if (d <= 1e-9) return false;
    a[j][j] = std::sqrt(d);
    for (int i = j + 1; i < N; ++i) {
      double v = a[i][j];
      for (int k = 0; k < j; ++k) v -= a[i][k] * a[j][k];
      a[i][j] = v / a[j][j];
    }
  }
  for (int i = 0; i < N; ++i) {
    double v = y[i];
    for (int k = 0; k < i; ++k) v -= a[i][k] * y[k];
    y[i] = v / a[i][i];
  }
  for (int i = N - 1; i >= 0; --i) {
    double v = y[i];
    for (int k = i + 1; k < N; ++k) v -= a[k][i] * y[k];
    y[i] = v / a[i][i];
  }
  return true;
}

// The integer range of dx for which lo <= dx * k + c <= hi (all dx when k ~ 0 and c fits).
void restrict(double k, double c, double lo, double hi, int& first, int& last) {
  if (std::abs(k) < 1e-12) {
    if (c < lo || c > hi) last = first - 1;
    return;
  }
  double x0 = (lo - c) / k, x1 = (hi - c) / k;
  if (x0 > x1) std::swap(x0, x1);
  first = std::max(first, static_cast<int>(std::ceil(x0 - 1e-9)));
  last = std::min(last, static_cast<int>(std::floor(x1 + 1e-9)));
}

template <typename T>
void gather(const cv::Mat& image, cv::Point c, cv::Point2d n, double offset,
            const EdgeProfileParams& params, float scale, Samples& out) {
  const int reach = edgeProfileReach(params);
  out.count = 0;
  double sum = 0;
  for (int dy = -reach; dy <= reach; ++dy) {
    int first = -reach, last = reach;
    // s = dx nx + dy ny within offset +- halfAcross; t = -dx ny + dy nx within +- halfAlong.
    restrict(n.x, dy * n.y, offset - params.halfAcross, offset + params.halfAcross, first, last);
    restrict(-n.y, dy * n.x, -params.halfAlong, params.halfAlong, first, last);
    const T* row = image.ptr<T>(c.y + dy) + c.x;
    for (int dx = first; dx <= last && out.count < kCapacity; ++dx) {
      const int i = out.count++;
      out.s[i] = static_cast<float>(dx * n.x + dy * n.y);
      out.t[i] = static_cast<float>(-dx * n.y + dy * n.x);
      out.v[i] = static_cast<float>(row[dx]) * scale;
      sum += out.v[i];
    }
  }
  out.mean = out.count ? static_cast<float>(sum / out.count) : 0.0f;
  for (int i = 0; i < out.count; ++i) out.v[i] -= out.mean;
}

// One Gauss-Newton step of the model v = a + b Phi(z), z = (s + phi t - e) / w, for (a, b, e)
// and, as the extra fourth unknown, either the width w (Extra::Width) or the turn phi of the
// normal (Extra::Turn). Returns false when the system is singular or the contrast not positive.
enum class Extra { None, Width, Turn };

template <Extra X>
bool step(const Samples& smp, double& a, double& b, double& e, double& w, double& phi) {
  constexpr int N = X == Extra::None ? 3 : 4;
  const NormalTable& table = normalTable();
  const float invW = static_cast<float>(1.0 / w), ef = static_cast<float>(e);
  const float phiF = static_cast<float>(phi);
  float acc[N][N + 1] = {};
  for (int i = 0; i < smp.count; ++i) {
    const float z = (smp.s[i] + phiF * smp.t[i] - ef) * invW;
    float cdf, pdf;
    table.lookup(z, cdf, pdf);
    float basis[4] = {1.0f, cdf, pdf, 0.0f};
    if constexpr (X == Extra::Width) basis[3] = z * pdf;
    if constexpr (X == Extra::Turn) basis[3] = smp.t[i] * pdf;
    for (int r = 0; r < N; ++r) {
      acc[r][N] += basis[r] * smp.v[i];
      for (int k = 0; k <= r; ++k) acc[r][k] += basis[r] * basis[k];
    }
  }
  std::array<std::array<double, N>, N> m{};
  std::array<double, N> y{};
  for (int r = 0; r < N; ++r) {
    y[r] = acc[r][N];
    for (int k = 0; k <= r; ++k) m[r][k] = acc[r][k];
  }
  if (!solveSpd<N>(m, y)) return false;
  a = y[0];
  b = y[1];
  if (b <= 1e-6) return false;
  // d/de = -b pdf / w, d/dw = -b z pdf / w, d/dphi = b t pdf / w.
  e += std::clamp(-y[2] * w / b, -0.5, 0.5);
  if constexpr (X == Extra::Width) w = std::clamp(w - y[3] * w / b, 0.3, 5.0);
  if constexpr (X == Extra::Turn) phi += std::clamp(y[3] * w / b, -0.2, 0.2);
  return true;
}

}  // namespace

int edgeProfileReach(const EdgeProfileParams& params) {
  return static_cast<int>(std::ceil(std::hypot(params.halfAcross + 1.5, params.halfAlong)));
}

std::optional<EdgePoint> fitEdgeProfile(const cv::Mat& image, cv::Point pixel, cv::Point2d normal,
                                        double offset, const EdgeProfileParams& params,
                                        double* fittedWidth) {
  thread_local Samples smp;
  if (image.depth() == CV_16U)
    gather<ushort>(image, pixel, normal, offset, params, 1.0f / 256, smp);
  else
    gather<uchar>(image, pixel, normal, offset, params, 1.0f, smp);
  if (smp.count < 12) return std::nullopt;

  // With a known width: (a, b, e) steps, the last one also turning the normal. Otherwise the
  // steps fit the width, and a final step the turn.
  const bool fitWidth = params.width <= 0;
  double a = 0, b = 0, e = offset, w = fitWidth ? params.initialWidth : params.width, phi = 0;
  const int iterations = std::max(1, params.iterations);
  for (int it = 0; it < iterations; ++it) {
    const bool last = it == iterations - 1;
    bool ok = true;
    if (fitWidth)
      ok = step<Extra::Width>(smp, a, b, e, w, phi) &&
           (!last || step<Extra::Turn>(smp, a, b, e, w, phi));
    else
      ok = last ? step<Extra::Turn>(smp, a, b, e, w, phi) : step<Extra::None>(smp, a, b, e, w, phi);
    if (!ok) return std::nullopt;
  }
  if (std::abs(e - offset) > 1.0) return std::nullopt;  // wandered off: not a clean edge
  if (fittedWidth) *fittedWidth = w;

  // The fitted line is {p : (p - c) . (n + phi t) = e}; the foot of the pixel centre on it lies
  // e / |n + phi t| along the turned unit normal.
  const cv::Point2d t{-normal.y, normal.x};
  cv::Point2d n = normal + phi * t;
  n /= std::hypot(n.x, n.y);
  return EdgePoint{cv::Point2d(pixel) + e / std::hypot(1.0, phi) * n, n,
                   b / (w * std::sqrt(2 * std::numbers::pi))};
}

double estimateEdgeWidth(const cv::Mat& image, const std::vector<EdgeSeed>& seeds,
                         const EdgeProfileParams& params, int maxSamples) {
  EdgeProfileParams fitParams = params;
  fitParams.width = 0;
  fitParams.iterations = std::max(params.iterations, 3);
  const int reach = edgeProfileReach(fitParams);
  std::vector<double> widths;
  const size_t stride = std::max<size_t>(1, seeds.size() / std::max(1, maxSamples));
  for (size_t i = 0; i < seeds.size(); i += stride) {
    const EdgeSeed& s = seeds[i];
    if (s.pixel.x < reach || s.pixel.y < reach || s.pixel.x >= image.cols - reach ||
        s.pixel.y >= image.rows - reach)
      continue;
    double w = 0;
    if (fitEdgeProfile(image, s.pixel, s.normal, s.offset, fitParams, &w)) widths.push_back(w);
  }
  if (widths.empty()) return params.initialWidth;
  std::nth_element(widths.begin(), widths.begin() + widths.size() / 2, widths.end());
  return widths[widths.size() / 2];
}

}  // namespace facet
