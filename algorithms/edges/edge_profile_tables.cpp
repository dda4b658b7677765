// Tabulated edge profiles for edge_profile_fit: the erf, and the exact profiles of a step blurred
// by a Gaussian and integrated over the pixel square, for both blur models.
#include "algorithms/edges/edge_profile_tables.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <mutex>
#include <numbers>
#include <utility>
#include <vector>

namespace facet::edge_profile {
namespace {

// Standard normal CDF and PDF, tabulated on [-kRange, kRange] with linear interpolation
// (step 1/64: interpolation error below 1e-5).
constexpr float kRange = 6.0f;
constexpr int kPerUnit = 64;
constexpr int kTableSize = static_cast<int>(2 * kRange * kPerUnit) + 2;

struct NormalTable {
  std::array<float, kTableSize> cdf{}, pdf{};
  // The same, packed per interval for the vectorised fit: value and slope of CDF and PDF.
  using Interval = ProfileInterval;
  std::array<Interval, kTableSize> packed{};
  NormalTable() {
    for (int i = 0; i < kTableSize; ++i) {
      const double z = -kRange + static_cast<double>(i) / kPerUnit;
      cdf[i] = static_cast<float>(0.5 * std::erfc(-z / std::numbers::sqrt2));
      pdf[i] = static_cast<float>(std::exp(-0.5 * z * z) / std::sqrt(2 * std::numbers::pi));
    }
    for (int i = 0; i + 1 < kTableSize; ++i)
      packed[i] = {cdf[i], cdf[i + 1] - cdf[i], pdf[i], pdf[i + 1] - pdf[i]};
    packed[kTableSize - 1] = {cdf[kTableSize - 1], 0, pdf[kTableSize - 1], 0};
  }
};

const NormalTable& normalTable() {
  static const NormalTable table;
  return table;
}

// The standard normal CDF Phi and its first and second antiderivatives G(x) = x Phi(x) + phi(x)
// and H(x) = ((x^2 + 1) Phi(x) + x phi(x)) / 2 at any x, for the aperture profiles below: a row
// of them needs about a thousand values, and erfc and exp at each made a row cost as much as the
// fits that use it. Tabulated at step 1/64 with each function's derivative, cubic Hermite
// interpolation (G' = Phi, H' = G, Phi' = phi) is within 1e-10 of the closed forms; beyond
// +-kOuter, Phi is 0 or 1 to double precision and G, H are their asymptotes.
struct Antiderivatives {
  double cdf, g, h;
};

class AntiderivativeTable {
 public:
  AntiderivativeTable() {
    for (int i = 0; i < kNodes; ++i) {
      const double x = -kOuter + static_cast<double>(i) / kPerUnit;
      const double phi = 0.5 * std::erfc(-x / std::numbers::sqrt2);
      const double density = std::exp(-0.5 * x * x) / std::sqrt(2 * std::numbers::pi);
      nodes_[i] = {phi, density, x * phi + density, 0.5 * ((x * x + 1) * phi + x * density)};
    }
  }

  Antiderivatives at(double x) const {
    // NaN (a failed width estimate upstream) stays NaN, as erfc would have kept it: a profile
    // of NaN never wins a comparison, where one of numbers might.
    if (std::isnan(x)) return {x, x, x};
    if (x <= -kOuter) return {0, 0, 0};
    if (x >= kOuter) return {1, x, 0.5 * (x * x + 1)};
    const double position = (x + kOuter) * kPerUnit;
    const int i = std::min(static_cast<int>(position), kNodes - 2);
    const double t = position - i;
    const Node& a = nodes_[i];
    const Node& b = nodes_[i + 1];
    // Cubic Hermite basis on [0, 1]; derivative terms scaled by the step 1/kPerUnit.
    const double t2 = t * t, t3 = t2 * t;
    const double h00 = 2 * t3 - 3 * t2 + 1, h01 = 1 - h00;
    const double h10 = (t3 - 2 * t2 + t) / kPerUnit, h11 = (t3 - t2) / kPerUnit;
    return {h00 * a.cdf + h01 * b.cdf + h10 * a.density + h11 * b.density,
            h00 * a.g + h01 * b.g + h10 * a.cdf + h11 * b.cdf,
            h00 * a.h + h01 * b.h + h10 * a.g + h11 * b.g};
  }

 private:
  static constexpr double kOuter = 9.0;
  static constexpr int kPerUnit = 64;
  static constexpr int kNodes = static_cast<int>(2 * kOuter * kPerUnit) + 1;
  struct Node {
    double cdf, density, g, h;
  };
  std::array<Node, kNodes> nodes_{};
};

const AntiderivativeTable& antiderivativeTable() {
  static const AntiderivativeTable table;
  return table;
}

// Profiles of a blurred step seen through the pixel aperture, for one PSF sigma and normal
// angles 0..45 degrees (1 degree steps; the profile depends only on {|cos|, |sin|}).
// For the unit pixel square the aperture projected on the normal is box(c) * box(s) with
// c = |cos|, s = |sin|, so with G(x) = x Phi(x) + phi(x) and H(x) = ((x^2 + 1) Phi(x) + x phi(x))/2
// (the first and second antiderivatives of Phi):
//   P(u)  = sigma^2 / (c s) [H((u+p)/sigma) - H((u+m)/sigma) - H((u-m)/sigma) + H((u-p)/sigma)]
//   P'(u) = sigma   / (c s) [G(...)         - G(...)         - G(...)         + G(...)]
// with p = (c + s)/2, m = (c - s)/2; for s -> 0 the single box gives
//   P(u) = sigma / c [G((u+c/2)/sigma) - G((u-c/2)/sigma)],  P'(u) = [Phi(..) - Phi(..)] / c.
constexpr float kApertureRange = 7.5f;  // pixels either side of the edge
constexpr int kAperturePerPixel = 16;
constexpr int kApertureSize = static_cast<int>(2 * kApertureRange * kAperturePerPixel) + 2;
constexpr int kApertureAngles = 46;
static_assert(kApertureSize == 2 * (kApertureSize / 2 - 1) + 2, "u = 0 is a sample");

}  // namespace

class ApertureProfiles {
 public:
  double sigma = 0;
  bool gridBlur = false;
  // kApertureAngles x kApertureSize, built on use: left uninitialised (178 KB per sigma and
  // model; a row is read only after buildRow has written all of it).
  std::unique_ptr<NormalTable::Interval[]> rows;
  std::unique_ptr<std::once_flag[]> built;
  std::vector<double> kernel;  // the grid model's sampled Gaussian, and its sum
  double kernelSum = 0;

  ApertureProfiles(double psfSigma, bool blurOnGrid)
      : sigma(psfSigma),
        gridBlur(blurOnGrid),
        rows(new NormalTable::Interval[static_cast<size_t>(kApertureAngles) * kApertureSize]),
        built(new std::once_flag[kApertureAngles]) {
    if (gridBlur) kernel = sampledGaussian(sigma, kernelSum);
  }

  void buildRow(int k) {
    std::vector<double> value(kApertureSize), slope(kApertureSize);
    {
      const double angle = k * std::numbers::pi / 180.0;
      const double c = std::cos(angle), sn = std::sin(angle);
      const GridTaps taps = gridBlur ? gridTaps(c, sn) : GridTaps();
      TapWindow window;
      const auto compute = [&](int i) {
        const double u = -kApertureRange + static_cast<double>(i) / kAperturePerPixel;
        if (gridBlur)
          gridProfile(taps, window, u, c, sn, value[i], slope[i]);
        else
          profile(u, c, sn, value[i], slope[i]);
      };
      // Both blurs and the pixel square are point-symmetric, so P(-u) = 1 - P(u) and
      // P'(-u) = P'(u): the samples up to u = 0 give those after it (the last one, past +range,
      // has no mirror).
      constexpr int kCentre = kApertureSize / 2 - 1;  // u = 0
      for (int i = 0; i <= kCentre; ++i) compute(i);
      for (int i = kCentre + 1; i < 2 * kCentre + 1; ++i) {
        value[i] = 1 - value[2 * kCentre - i];
        slope[i] = slope[2 * kCentre - i];
      }
      compute(kApertureSize - 1);
      NormalTable::Interval* row = &rows[static_cast<size_t>(k) * kApertureSize];
      for (int i = 0; i < kApertureSize; ++i) {
        const int j = std::min(i + 1, kApertureSize - 1);
        row[i] = {static_cast<float>(value[i]), static_cast<float>(value[j] - value[i]),
                  static_cast<float>(slope[i]), static_cast<float>(slope[j] - slope[i])};
      }
    }
  }

  ProfileView view(cv::Point2d normal, int degreeStep) {
    const double lo = std::min(std::abs(normal.x), std::abs(normal.y));
    const double hi = std::max(std::abs(normal.x), std::abs(normal.y));
    // The nearest whole degree of atan(lo / hi), by comparing with tan(k + 1/2 degree).
    static const std::array<double, kApertureAngles> tanHalf = [] {
      std::array<double, kApertureAngles> t{};
      for (int k = 0; k < kApertureAngles; ++k) t[k] = std::tan((k + 0.5) * std::numbers::pi / 180);
      return t;
    }();
    const double ratio = hi > 0 ? lo / hi : 0.0;
    const int degree = std::min(
        static_cast<int>(std::lower_bound(tanHalf.begin(), tanHalf.end(), ratio) - tanHalf.begin()),
        kApertureAngles - 1);
    const int k = degreeStep > 1 ? std::min((degree + degreeStep / 2) / degreeStep * degreeStep,
                                            kApertureAngles - 1)
                                 : degree;
    std::call_once(built[k], [this, k] { buildRow(k); });
    return {&rows[static_cast<size_t>(k) * kApertureSize],
            kApertureSize,
            1.0f,
            kApertureRange,
            static_cast<float>(kAperturePerPixel),
            1.0};
  }

 private:
  // The sharp step integrated over the pixel square: the CDF and density of the aperture
  // box(c) * box(s) at x.
  static void sharpStep(double x, double c, double s, double& value, double& slope) {
    if (s < 1e-6) {
      value = std::clamp((x + c / 2) / c, 0.0, 1.0);
      slope = std::abs(x) < c / 2 ? 1 / c : 0.0;
      return;
    }
    const double p = (c + s) / 2, m = (c - s) / 2;
    if (x <= -p) {
      value = 0, slope = 0;
    } else if (x <= -m) {
      value = (x + p) * (x + p) / (2 * c * s), slope = (x + p) / (c * s);
    } else if (x <= m) {
      value = s / (2 * c) + (x + m) / c, slope = 1 / c;
    } else if (x < p) {
      value = 1 - (p - x) * (p - x) / (2 * c * s), slope = (p - x) / (c * s);
    } else {
      value = 1, slope = 0;
    }
  }

  // Blur on the pixel grid: the pixel-integrated sharp step convolved with the sampled Gaussian
  // kernel (truncated at 4 sigma, normalised), as a blur applied to the sampled image does:
  //   P(u) = sum_k g(kx) g(ky) sharpStep(u - kx c - ky s).
  // The kernel's taps projected on the normal, sorted by offset t = kx c + ky s, with their
  // weights and the running sum of the weights before each: a tap farther than the aperture's
  // half width p = (c + s) / 2 from u adds 0 or its whole weight, so only the few taps within p
  // of u need the sharp step (a row of the table took 81 of them per sample at sigma 1).
  struct GridTaps {
    std::vector<double> offset, weight, before;
  };

  // The Gaussian sampled at whole pixels, truncated at 4 sigma, and its sum (the taps divide
  // by it).
  static std::vector<double> sampledGaussian(double sigma, double& sum) {
    const int r = static_cast<int>(std::ceil(4 * sigma));
    std::vector<double> kernel(2 * r + 1);
    sum = 0;
    for (int k = -r; k <= r; ++k) sum += kernel[k + r] = std::exp(-0.5 * k * k / (sigma * sigma));
    return kernel;
  }

  GridTaps gridTaps(double c, double s) const {
    const int r = static_cast<int>(kernel.size() / 2);
    std::vector<std::pair<double, double>> taps;
    if (s < 1e-9) {  // axis-aligned: the kernel's rows all project to the same offsets
      taps.reserve(kernel.size());
      for (int kx = -r; kx <= r; ++kx) taps.push_back({kx * c, kernel[kx + r] / kernelSum});
    } else {
      taps.reserve(kernel.size() * kernel.size());
      for (int ky = -r; ky <= r; ++ky)
        for (int kx = -r; kx <= r; ++kx)
          taps.push_back(
              {kx * c + ky * s, kernel[kx + r] * kernel[ky + r] / (kernelSum * kernelSum)});
    }
    std::sort(taps.begin(), taps.end());
    GridTaps out;
    out.offset.reserve(taps.size());
    out.weight.reserve(taps.size());
    out.before.reserve(taps.size() + 1);
    double running = 0;
    for (const auto& [t, w] : taps) {
      out.offset.push_back(t);
      out.weight.push_back(w);
      out.before.push_back(running);
      running += w;
    }
    out.before.push_back(running);
    return out;
  }

  // The taps within p of u: [first, end). A row's u only grows, so both ends only move forward.
  struct TapWindow {
    std::size_t first = 0, end = 0;
  };

  static void gridProfile(const GridTaps& taps, TapWindow& window, double u, double c, double s,
                          double& value, double& slope) {
    const double p = (c + s) / 2;
    // Taps with u - t >= p see the whole step (1); those with u - t <= -p see none of it.
    const std::size_t count = taps.offset.size();
    while (window.first < count && taps.offset[window.first] <= u - p) ++window.first;
    window.end = std::max(window.end, window.first);
    while (window.end < count && taps.offset[window.end] < u + p) ++window.end;
    std::size_t i = window.first;
    const std::size_t end = window.end;
    value = taps.before[i];
    slope = 0;
    for (; i < end; ++i) {
      double v, d;
      sharpStep(u - taps.offset[i], c, s, v, d);
      value += taps.weight[i] * v;
      slope += taps.weight[i] * d;
    }
  }

  void profile(double u, double c, double s, double& value, double& slope) const {
    const double sg = sigma;
    if (s < 1e-3) {
      const auto& t = antiderivativeTable();
      const Antiderivatives a = t.at((u + c / 2) / sg), b = t.at((u - c / 2) / sg);
      value = sg / c * (a.g - b.g);
      slope = (a.cdf - b.cdf) / c;
      return;
    }
    const double p = (c + s) / 2, m = (c - s) / 2;
    const auto& t = antiderivativeTable();
    const Antiderivatives pp = t.at((u + p) / sg), pm = t.at((u + m) / sg), mm = t.at((u - m) / sg),
                          mp = t.at((u - p) / sg);
    value = sg * sg / (c * s) * (pp.h - pm.h - mm.h + mp.h);
    slope = sg / (c * s) * (pp.g - pm.g - mm.g + mp.g);
  }
};

// Profiles are pure functions of sigma; keep the last few so that a camera's images (whose blur
// estimate varies little) build them once.
std::shared_ptr<ApertureProfiles> apertureProfiles(double sigma, bool gridBlur) {
  static std::mutex mutex;
  static std::vector<std::shared_ptr<ApertureProfiles>> cache;
  const double key = std::round(sigma * 50) / 50;
  // The profile fit asks for the same profiles at every point of an image: the thread's last
  // answer spares the lock and the search (an entry evicted meanwhile holds the same values).
  thread_local std::shared_ptr<ApertureProfiles> last;
  if (last && last->sigma == key && last->gridBlur == gridBlur) return last;
  std::lock_guard lock(mutex);
  for (const auto& p : cache)
    if (p->sigma == key && p->gridBlur == gridBlur) return last = p;
  auto made = std::make_shared<ApertureProfiles>(key, gridBlur);
  if (cache.size() >= 64) cache.erase(cache.begin());
  cache.push_back(made);
  return last = made;
}

ProfileView erfView(double w) {
  const auto& t = normalTable();
  return {t.packed.data(),
          kTableSize,
          static_cast<float>(1.0 / w),
          kRange,
          static_cast<float>(kPerUnit),
          w};
}

ProfileView apertureView(ApertureProfiles& profiles, cv::Point2d normal, int degreeStep) {
  return profiles.view(normal, degreeStep);
}

}  // namespace facet::edge_profile
