#include "algorithms/registration/rotation_scale_vote.hpp"

#include <algorithm>
#include <cmath>

namespace facet {

std::vector<int> agreeingRotationScale(const std::vector<FeatureMatch>& m, double maxRotationDeg,
                                       double maxLog2Scale) {
  std::vector<int> keep(m.size());
  for (std::size_t i = 0; i < m.size(); ++i) keep[i] = static_cast<int>(i);
  if (maxRotationDeg <= 0 || m.size() < 8) return keep;
  constexpr int kTurns = 36, kScales = 20;  // 10 degrees; half octaves over +-5 octaves
  auto turnOf = [](double deg) {
    const int b = static_cast<int>(std::floor((deg + 180.0) / 10.0));
    return ((b % kTurns) + kTurns) % kTurns;
  };
  auto scaleOf = [](double log2Scale) {
    return std::clamp(static_cast<int>(std::floor((log2Scale + 5.0) * 2.0)), 0, kScales - 1);
  };
  std::vector<int> hist(kTurns * kScales, 0);
  for (const auto& x : m) ++hist[turnOf(x.rotationDeg) * kScales + scaleOf(std::log2(x.scale))];
  int peakTurn = 0, peakScale = 0, peakVotes = -1;
  for (int t = 0; t < kTurns; ++t)
    for (int c = 0; c < kScales; ++c) {
      int votes = 0;
      for (int dt = -1; dt <= 1; ++dt)
        for (int dc = std::max(0, c - 1); dc <= std::min(kScales - 1, c + 1); ++dc)
          votes += hist[((t + dt + kTurns) % kTurns) * kScales + dc];
      if (votes > peakVotes) {
        peakVotes = votes;
        peakTurn = t;
        peakScale = c;
      }
    }
  const double peakDeg = peakTurn * 10.0 - 175.0;
  std::vector<double> peakLogScales;
  for (const auto& x : m) {
    const int dt = std::abs(turnOf(x.rotationDeg) - peakTurn);
    if (std::min(dt, kTurns - dt) <= 1 && std::abs(scaleOf(std::log2(x.scale)) - peakScale) <= 1)
      peakLogScales.push_back(std::log2(x.scale));
  }
  std::nth_element(peakLogScales.begin(), peakLogScales.begin() + peakLogScales.size() / 2,
                   peakLogScales.end());
  const double peakLog2Scale = peakLogScales[peakLogScales.size() / 2];
  keep.clear();
  for (std::size_t i = 0; i < m.size(); ++i) {
    const double d = std::abs(std::remainder(m[i].rotationDeg - peakDeg, 360.0));
    if (d <= maxRotationDeg &&
        (maxLog2Scale <= 0 || std::abs(std::log2(m[i].scale) - peakLog2Scale) <= maxLog2Scale))
      keep.push_back(static_cast<int>(i));
  }
  return keep;
}

}  // namespace facet
