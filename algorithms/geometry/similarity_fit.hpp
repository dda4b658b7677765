#pragma once
// The least-squares similarity (rotation, uniform scale, translation) taking one point set onto
// another: Umeyama's closed form in 2D. With centred points p_i, q_i it minimises
// sum |q_i - M p_i|^2 over M = k [[cos a, sin a], [-sin a, cos a]] (the project's pose
// convention: a turns counter-clockwise on screen).

#include <cmath>
#include <numbers>
#include <optional>
#include <vector>

#include <opencv2/core.hpp>

namespace facet {

struct SimilarityFit {
  cv::Matx33d H = cv::Matx33d::eye();  // from -> to, last row (0, 0, 1)
  double rotationDeg = 0;              // a, counter-clockwise on screen
  double scale = 1;                    // k
};

// Needs two or more pairs, not all `from` points at one place; nothing otherwise.
[[nodiscard]] inline std::optional<SimilarityFit> fitSimilarity(
    const std::vector<cv::Point2d>& from, const std::vector<cv::Point2d>& to) {
  if (from.size() < 2 || from.size() != to.size()) return std::nullopt;
  cv::Point2d mf(0, 0), mt(0, 0);
  for (std::size_t i = 0; i < from.size(); ++i) mf += from[i], mt += to[i];
  mf *= 1.0 / static_cast<double>(from.size());
  mt *= 1.0 / static_cast<double>(to.size());
  double c = 0, s = 0, var = 0;  // k var cos a, k var sin a, sum |p|^2
  for (std::size_t i = 0; i < from.size(); ++i) {
    const cv::Point2d p = from[i] - mf, q = to[i] - mt;
    c += p.x * q.x + p.y * q.y;
    s += p.y * q.x - p.x * q.y;
    var += p.dot(p);
  }
  if (!(var > 0)) return std::nullopt;
  SimilarityFit fit;
  const double a = c / var, b = s / var;
  fit.H = {a, b, mt.x - (a * mf.x + b * mf.y), -b, a, mt.y - (-b * mf.x + a * mf.y), 0, 0, 1};
  fit.rotationDeg = std::atan2(s, c) * 180.0 / std::numbers::pi;
  fit.scale = std::hypot(c, s) / var;
  return fit;
}

}  // namespace facet
