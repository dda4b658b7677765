#pragma once
// The standard normal density phi(z) and distribution Phi(z) from one exponential, for the fits
// of blurred steps in grey profiles (profile_edges.cpp, edge_cluster_fit.cpp): erf by
// Abramowitz & Stegun 7.1.26 (|error| < 1.5e-7, i.e. < 1e-4 grey levels on a 255 step). The fits
// evaluate them a few thousand times per edge; std::erfc costs several times more.

#include <cmath>

namespace facet::standard_normal {

struct Normal {
  double density, cdf;
};

// From z and exp(-z^2 / 2).
inline Normal normal(double z, double e) {
  const double x = std::abs(z) * M_SQRT1_2;
  const double t = 1.0 / (1.0 + 0.3275911 * x);
  const double poly =
      t *
      (0.254829592 + t * (-0.284496736 + t * (1.421413741 + t * (-1.453152027 + t * 1.061405429))));
  const double half = 0.5 * poly * e;  // 0.5 * erfc(x)
  return {0.3989422804014327 * e, z >= 0 ? 1.0 - half : half};
}

inline Normal normal(double z) {
  return normal(z, std::exp(-0.5 * z * z));
}

}  // namespace facet::standard_normal
