#include "algorithms/circle/censored_pixels.hpp"

#include "algorithms/circle/rim_band.hpp"

namespace facet {

CensoredPixels::CensoredPixels(std::span<const double> grey, double clipLevel)
    : clipLevel_(clipLevel) {
  for (std::size_t i = 0; i < grey.size(); ++i)
    if (grey[i] >= clipLevel || grey[i] <= 0.0) {
      index_.push_back(i);
      high_.push_back(grey[i] >= clipLevel);
    }
}

void CensoredPixels::censor(std::span<double> residuals) const {
  for (std::size_t k = 0; k < index_.size(); ++k) {
    double& r = residuals[index_[k]];
    if (high_[k] ? r < 0.0 : r > 0.0) r = 0.0;
  }
}

void CensoredPixels::unweight(std::span<const double> residuals, std::span<double> weights) const {
  for (const std::size_t i : index_)
    if (residuals[i] == 0.0) weights[i] = 0.0;
}

double CensoredPixels::robustSigma(std::span<const double> residuals) const {
  if (index_.empty() || index_.size() == residuals.size()) return rim_band::robustSigma(residuals);
  std::vector<double> observed;
  observed.reserve(residuals.size() - index_.size());
  std::size_t next = 0;
  for (std::size_t i = 0; i < residuals.size(); ++i) {
    const bool clipped = next < index_.size() && index_[next] == i;
    next += clipped ? 1 : 0;
    if (!clipped) observed.push_back(residuals[i]);
  }
  return rim_band::robustSigma(observed);
}

double CensoredPixels::startingLevel(double level, double other, double clipLevel) {
  if (level >= clipLevel) return clipLevel + 0.5 * (clipLevel - other);
  if (level <= 0.0) return -0.5 * other;
  return level;
}

CensoredPixels::Step CensoredPixels::startingStep(double outside, double inside, double clipLevel) {
  const double level = startingLevel(outside, inside, clipLevel);
  return {level, startingLevel(inside, outside, clipLevel) - level};
}

bool CensoredPixels::middleSeen(double level, double contrast) const {
  const double middle = level + contrast / 2.0;
  return index_.empty() || (middle < clipLevel_ && middle > 0.0);
}

}  // namespace facet
