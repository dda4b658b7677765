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
  // Each match's bins and log2 scale, once.
  std::vector<int> turns(m.size()), scales(m.size());
  std::vector<double> log2Scales(m.size());
  std::vector<int> hist(kTurns * kScales, 0);
  for (std::size_t i = 0; i < m.size(); ++i) {
    log2Scales[i] = std::log2(m[i].scale);
    turns[i] = turnOf(m[i].rotationDeg);
    scales[i] = scaleOf(log2Scales[i]);
    ++hist[turns[i] * kScales + scales[i]];
  }
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
  for (std::size_t i = 0; i < m.size(); ++i) {
    const int dt = std::abs(turns[i] - peakTurn);
    if (std::min(dt, kTurns - dt) <= 1 && std::abs(scales[i] - peakScale) <= 1)
      peakLogScales.push_back(log2Scales[i]);
  }
  std::nth_element(peakLogScales.begin(), peakLogScales.begin() + peakLogScales.size() / 2,
                   peakLogScales.end());
  const double peakLog2Scale = peakLogScales[peakLogScales.size() / 2];
  keep.clear();
  for (std::size_t i = 0; i < m.size(); ++i) {
    const double d = std::abs(std::remainder(m[i].rotationDeg - peakDeg, 360.0));
    if (d <= maxRotationDeg &&
        (maxLog2Scale <= 0 || std::abs(log2Scales[i] - peakLog2Scale) <= maxLog2Scale))
      keep.push_back(static_cast<int>(i));
  }
  return keep;
}

}  // namespace facet
