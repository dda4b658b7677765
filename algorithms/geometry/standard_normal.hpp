#pragma once
// The standard normal distribution from one exponential, for the fits of blurred steps (the
// caliper's profile edges, the circle's grey-value rim): erfc by Abramowitz & Stegun 7.1.26
// (|error| < 1.5e-7, i.e. < 1e-4 grey levels on a 255 step). The fits evaluate it thousands of
// times; std::erfc costs several times more, and their Jacobians need the exponential anyway.

#include <cmath>

namespace facet::standard_normal {

// erfc(x) / 2 for x >= 0, given e = exp(-x^2).
inline double halfErfc(double x, double e) {
  const double t = 1.0 / (1.0 + 0.3275911 * x);
  const double poly =
      t *
      (0.254829592 + t * (-0.284496736 + t * (1.421413741 + t * (-1.453152027 + t * 1.061405429))));
  return 0.5 * poly * e;
}

struct Normal {
  double density, cdf;
};

// The density phi(z) and distribution Phi(z), from z and e = exp(-z^2 / 2).
inline Normal normal(double z, double e) {
  const double half = halfErfc(std::abs(z) * M_SQRT1_2, e);
  return {0.3989422804014327 * e, z >= 0 ? 1.0 - half : half};
}

inline Normal normal(double z) {
  return normal(z, std::exp(-0.5 * z * z));
}

}  // namespace facet::standard_normal
