// The geometric circle fit's coverage: from the points, and from their sorted polar angles (what
// measureCircle passes on when the stray-arc check has sorted them already) alike.
#include <algorithm>
#include <cmath>
#include <numbers>
#include <random>
#include <vector>

#include <gtest/gtest.h>

#include "algorithms/circle/circle_fit.hpp"

namespace facet::circle_fit {
namespace {

constexpr double kPi = std::numbers::pi;

// Points on a circle of radius r around (40, 30) at the given angles (radians), jittered by up to
// 0.2 px.
std::vector<Eigen::Vector2d> rim(const std::vector<double>& angles, double r) {
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> jitter(-0.2, 0.2);
  std::vector<Eigen::Vector2d> pts;
  for (double a : angles)
    pts.emplace_back(40.0 + (r + jitter(rng)) * std::cos(a),
                     30.0 + (r + jitter(rng)) * std::sin(a));
  return pts;
}

std::vector<double> sortedAngles(const std::vector<Eigen::Vector2d>& pts, const Circle& c) {
  std::vector<double> a;
  for (const auto& p : pts) a.push_back(std::atan2(p.y() - c.centre.y(), p.x() - c.centre.x()));
  std::sort(a.begin(), a.end());
  return a;
}

TEST(CircleCoverage, SortedAnglesGiveThePointsCoverage) {
  const Circle c{{40.0, 30.0}, 20.0};
  // A rim with a 90 degree gap through +-180 degrees, a 40 degree gap and single missing points.
  std::vector<double> angles;
  for (int d = -89; d <= 89; d += 2)
    if (!(d > 10 && d < 50) && d != -31 && d != 61) angles.push_back(d * kPi / 180.0);
  const auto pts = rim(angles, c.radius);
  const double fromPoints = coverageDeg(pts, c);
  EXPECT_EQ(coverageDeg(sortedAngles(pts, c), c.radius), fromPoints);
  EXPECT_NEAR(fromPoints, 360.0 - 182.0 - 42.0, 1.0);
}

TEST(CircleCoverage, FewerThanTwoPointsCoverNothing) {
  const Circle c{{40.0, 30.0}, 20.0};
  EXPECT_EQ(coverageDeg(std::vector<double>{}, c.radius), 0.0);
  EXPECT_EQ(coverageDeg(std::vector<double>{0.5}, c.radius), 0.0);
  EXPECT_EQ(coverageDeg(rim({0.5}, c.radius), c), 0.0);
}

}  // namespace
}  // namespace facet::circle_fit
