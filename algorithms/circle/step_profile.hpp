#pragma once
// The blurred step's profile for the grey-value circle fit (circle_profile_fit.cpp): the Gaussian
// exp(-z^2 / 2) and the normal distribution's upper tail, in plain arithmetic without library
// calls or branches, so that the fit's loops over the rim band vectorise (std::exp is a call per
// pixel; it was a fifth of the fit's time).

#include <algorithm>
#include <bit>
#include <cmath>
#include <cstdint>
#include <numbers>

#include "algorithms/circle/pixel_pass.hpp"
#include "algorithms/geometry/standard_normal.hpp"

namespace facet::step_profile {

// exp(x) for x <= 0, within 3e-13 relative of std::exp (flushed to zero below -708, where
// std::exp is already smaller than 1e-307). Cody-Waite reduction x = k ln2 + r with
// |r| <= ln2 / 2, Taylor series of exp(r) to degree 10 (truncation below 2.2e-13), times 2^k built
// in the exponent bits. The profile's upper tail is good to 1.5e-7 (below): degree 13 (1e-17)
// bought nothing and cost three more multiply-adds per pixel and evaluation.
inline double expNonPositive(double x) {
  constexpr double kLog2e = 1.4426950408889634;
  constexpr double kLn2Hi = 6.93147180369123816490e-01;  // ln 2 with trailing zero bits: k ln2hi
  constexpr double kLn2Lo = 1.90821492927058770002e-10;  // is exact for |k| < 2^11
  constexpr double kRound = 6755399441055744.0;          // 1.5 * 2^52: adding it rounds to integer
  const double clamped = x < -708.0 ? -708.0 : x;
  const double shifted = clamped * kLog2e + kRound;  // k in the low bits of the mantissa
  const double k = shifted - kRound;
  const double r = (clamped - k * kLn2Hi) - k * kLn2Lo;
  double poly = 1.0 / 3628800.0;  // 1 / 10!
  poly = poly * r + 1.0 / 362880.0;
  poly = poly * r + 1.0 / 40320.0;
  poly = poly * r + 1.0 / 5040.0;
  poly = poly * r + 1.0 / 720.0;
  poly = poly * r + 1.0 / 120.0;
  poly = poly * r + 1.0 / 24.0;
  poly = poly * r + 1.0 / 6.0;
  poly = poly * r + 0.5;
  poly = poly * r + 1.0;
  poly = poly * r + 1.0;
  // k + 1023 in [1, 1023]: a normal power of two. The shift drops the bits of kRound.
  const std::uint64_t bits = (std::bit_cast<std::uint64_t>(shifted) + 1023u) << 52;
  const double scaled = poly * std::bit_cast<double>(bits);
  return x < -708.0 ? 0.0 : scaled;
}

// The Gaussian exp(-z^2 / 2).
inline double gaussian(double z) {
  return expNonPositive(-0.5 * z * z);
}

// Upper tail 1 - Phi(z) of the standard normal, given gauss = exp(-z^2 / 2): the Abramowitz &
// Stegun erfc of standard_normal.hpp (absolute error below 1.5e-7), which reuses the exponential
// the Jacobian needs.
inline double upperTail(double z, double gauss) {
  const double tail = standard_normal::halfErfc(std::abs(z) / std::numbers::sqrt2, gauss);
  return z >= 0.0 ? tail : 1.0 - tail;
}

// A blurred step seen through square pixels: the grey of a pixel whose centre lies d px outside
// an edge with unit normal (nx, ny), a step Phi(-x / s) (s: the lens's blur) averaged over the
// pixel's area. The pixel's projection on the normal spreads x by the sum of two uniform
// variables of widths |nx| and |ny|, so the average is a second difference of the step's second
// antiderivative. The Gaussian profile with s^2 = sigma^2 + 1/12 stands in for it when the lens
// blur is wide; at a blur of a third of a pixel and below (a sharp lens, an exact render) the
// pixel's box dominates and only this is right. Plain library calls: it serves the sharp images'
// refit, not the vectorised loops.
struct PixelStep {
  double value;  // the pixel's mean of Phi(-x / s)
  double dd;     // its derivative along d
  double ds;     // and along s
};
// Variance of a square pixel's area along any direction, px^2.
constexpr double kPixelVariance = 1.0 / 12.0;
// The Gaussian profile's blur below which the grey-value fits refit with pixelStep: the Gaussian
// s of a lens blur of 0.35 px (s^2 = sigma^2 + 1/12).
constexpr double kSharpBlur = 0.45;

// The lens's blur within a Gaussian profile's s (s^2 = sigma^2 + 1/12), the pixel model's start;
// held at 0.1 px where s leaves less than that.
inline double lensBlurOf(double gaussianBlur) {
  return std::sqrt(std::max(gaussianBlur * gaussianBlur - kPixelVariance, 0.01));
}
// The Gaussian equivalent of a lens blur seen through square pixels: the variance across a rim,
// PSF and pixel together, that moves the 50% level inside a convex rim.
inline double equivalentBlur(double lensBlur) {
  return std::sqrt(lensBlur * lensBlur + kPixelVariance);
}

inline PixelStep pixelStep(double d, double s, double nx, double ny) {
  const double inv = 1.0 / s;
  auto tail = [](double u) { return 0.5 * std::erfc(u / std::numbers::sqrt2); };  // Phi(-u)
  auto pdf = [](double u) { return std::exp(-0.5 * u * u) / std::sqrt(2.0 * std::numbers::pi); };
  // H1(u) = integral of Phi(-v) from u to infinity, H2(u) = integral of H1 from u to infinity.
  auto h1 = [&](double u) { return pdf(u) - u * tail(u); };
  auto h2 = [&](double u) { return 0.5 * ((1.0 + u * u) * tail(u) - u * pdf(u)); };
  const double a = std::max(std::abs(nx), std::abs(ny)), b = std::min(std::abs(nx), std::abs(ny));
  if (b < 1e-3) {  // along a pixel axis: one uniform of width a (the other's share is O(b^2))
    const double v1 = (d - 0.5 * a) * inv, v2 = (d + 0.5 * a) * inv;
    return {s / a * (h1(v1) - h1(v2)), (tail(v2) - tail(v1)) / a, (pdf(v1) - pdf(v2)) / a};
  }
  const double u[4] = {(d - 0.5 * (a + b)) * inv, (d - 0.5 * (a - b)) * inv,
                       (d + 0.5 * (a - b)) * inv, (d + 0.5 * (a + b)) * inv};
  const double sign[4] = {1.0, -1.0, -1.0, 1.0};
  double sum2 = 0.0, sum1 = 0.0, sumU1 = 0.0;
  for (int i = 0; i < 4; ++i) {
    const double g1 = h1(u[i]);
    sum2 += sign[i] * h2(u[i]);
    sum1 += sign[i] * g1;
    sumU1 += sign[i] * u[i] * g1;
  }
  const double k = s / (a * b);
  return {k * s * sum2, -k * sum1, k * (2.0 * sum2 + sumU1)};
}

}  // namespace facet::step_profile
