#pragma once
// Generic RANSAC (Fischler & Bolles 1981) with the adaptive stopping rule: the number of
// iterations shrinks as better consensus sets are found, so that with probability `confidence`
// at least one sample was outlier-free.

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <optional>
#include <random>
#include <vector>

namespace facet {

struct RansacParams {
  double inlierThreshold = 1.0;  // residual (same unit as the model's residual) for an inlier
  double confidence = 0.999;     // probability of drawing one all-inlier sample
  int maxIterations = 2000;
  std::uint64_t seed = 0x5eed;  // fixed seed: results are reproducible run to run
};

template <class Model>
struct RansacResult {
  Model model;
  std::vector<std::size_t> inliers;  // indices into the data
};

// fit(sampleIndices) -> std::optional<Model> builds a model from a minimal sample;
// residual(model, i) -> double gives the residual of datum i.
template <class Model, class Fit, class Residual>
std::optional<RansacResult<Model>> ransac(std::size_t dataCount, std::size_t sampleSize, Fit&& fit,
                                          Residual&& residual, const RansacParams& params = {}) {
  if (dataCount < sampleSize || sampleSize == 0) return std::nullopt;
  std::mt19937_64 rng(params.seed);
  std::optional<RansacResult<Model>> best;
  std::vector<std::size_t> sample(sampleSize);
  std::vector<std::size_t> inliers;
  double needed = params.maxIterations;
  for (int it = 0; it < params.maxIterations && it < needed; ++it) {
    // Draw a sample without repetition (rejection is cheap for small sample sizes).
    for (std::size_t k = 0; k < sampleSize; ++k) {
      std::size_t idx;
      do {
        idx = std::uniform_int_distribution<std::size_t>(0, dataCount - 1)(rng);
      } while (std::find(sample.begin(), sample.begin() + k, idx) != sample.begin() + k);
      sample[k] = idx;
    }
    std::optional<Model> model = fit(sample);
    if (!model) continue;
    inliers.clear();
    for (std::size_t i = 0; i < dataCount; ++i)
      if (residual(*model, i) <= params.inlierThreshold) inliers.push_back(i);
    if (!best || inliers.size() > best->inliers.size()) {
      best = RansacResult<Model>{*model, inliers};
      const double w = static_cast<double>(inliers.size()) / static_cast<double>(dataCount);
      const double pAllIn = std::pow(w, static_cast<double>(sampleSize));
      if (pAllIn >= 1.0) break;
      if (pAllIn > 0.0) needed = std::log(1.0 - params.confidence) / std::log(1.0 - pAllIn);
    }
  }
  return best;
}

}  // namespace facet
