// The elliptic rim: the ellipse grown from the arcs a circle kept, its distance and normal, the
// map that makes it a circle, and the second-harmonic test that tells an ellipse from a circle.
#include <algorithm>
#include <cmath>
#include <numbers>
#include <random>
#include <vector>

#include <gtest/gtest.h>

#include "algorithms/circle/rim_ellipse.hpp"

namespace facet::rim_ellipse {
namespace {

constexpr double kPi = std::numbers::pi;

// A hole of radius 30 px seen at a tilt of about 26 degrees: axes 30 and 27 px, the major one
// 25 degrees below the image's x axis (y down), about a subpixel centre.
Ellipse tilted() {
  return {{412.37, 288.81}, 30.0, 27.0, {std::cos(25 * kPi / 180), std::sin(25 * kPi / 180)}};
}

Eigen::Vector2d pointAt(const Ellipse& e, double t) {
  const Eigen::Vector2d minorAxis{-e.axis.y(), e.axis.x()};
  return e.centre + e.major * std::cos(t) * e.axis + e.minor * std::sin(t) * minorAxis;
}

// Edge points all around the ellipse, moved along its normal by noise of sigma 0.03 px, with their
// gradient directions (outwards).
struct Rim {
  std::vector<Eigen::Vector2d> points, normals;
};
Rim rimOf(const Ellipse& e, int n) {
  std::mt19937 rng(5);
  std::normal_distribution<double> noise(0.0, 0.03);
  Rim rim;
  for (int i = 0; i < n; ++i) {
    const Eigen::Vector2d p = pointAt(e, 2 * kPi * i / n);
    rim.normals.push_back(outwardNormal(e, p));
    rim.points.push_back(p + noise(rng) * rim.normals.back());
  }
  return rim;
}

TEST(RimEllipse, DistanceIsExactOnTheAxesAndSignedOutwards) {
  const Ellipse e = tilted();
  const Eigen::Vector2d minorAxis{-e.axis.y(), e.axis.x()};
  EXPECT_NEAR(residual(e, e.centre + 30.4 * e.axis), 0.4, 1e-12);
  EXPECT_NEAR(residual(e, e.centre - 26.5 * minorAxis), -0.5, 1e-12);
  // Elsewhere first order: within 0.002 px at 0.3 px from the rim.
  for (double t = 0.1; t < 2 * kPi; t += 0.37) {
    const Eigen::Vector2d on = pointAt(e, t), n = outwardNormal(e, on);
    EXPECT_NEAR(residual(e, on + 0.3 * n), 0.3, 0.002) << t;
    EXPECT_NEAR(n.norm(), 1.0, 1e-12);
  }
}

TEST(RimEllipse, TheMapToACircleKeepsTheAreaAndMakesTheRimRound) {
  const Ellipse e = tilted();
  const cv::Matx22d w = e.toCircle();
  EXPECT_NEAR(cv::determinant(w), 1.0, 1e-12);
  EXPECT_NEAR(e.meanRadius(), std::sqrt(30.0 * 27.0), 1e-12);
  for (double t = 0.0; t < 2 * kPi; t += 0.5) {
    const Eigen::Vector2d d = pointAt(e, t) - e.centre;
    EXPECT_NEAR(cv::norm(w * cv::Vec2d(d.x(), d.y())), e.meanRadius(), 1e-9) << t;
  }
}

TEST(RimEllipse, GrowsFromTheArcsACircleKeptToTheWholeRim) {
  const Ellipse truth = tilted();
  const Rim rim = rimOf(truth, 360);
  // What a circle's 0.5 px band keeps of this rim: two opposite arcs near the mean radius.
  std::vector<Eigen::Vector2d> seed;
  for (const auto& p : rim.points)
    if (std::abs((p - truth.centre).norm() - truth.meanRadius()) < 0.5) seed.push_back(p);
  ASSERT_LT(seed.size(), rim.points.size() / 2);
  const auto fit = fitRimEllipse(rim.points, rim.normals, seed, 0.5, std::cos(12 * kPi / 180));
  ASSERT_TRUE(fit);
  EXPECT_EQ(fit->inliers.size(), rim.points.size());
  EXPECT_NEAR(fit->ellipse.centre.x(), truth.centre.x(), 0.01);
  EXPECT_NEAR(fit->ellipse.centre.y(), truth.centre.y(), 0.01);
  EXPECT_NEAR(fit->ellipse.major, 30.0, 0.01);
  EXPECT_NEAR(fit->ellipse.minor, 27.0, 0.01);
  EXPECT_NEAR(std::abs(fit->ellipse.axis.dot(truth.axis)), 1.0, 1e-5);
  EXPECT_NEAR(fit->rms, 0.03, 0.006);
  EXPECT_GT(fit->fStatistic, 1000.0);  // a circle is no model of this rim
}

TEST(RimEllipse, PointsOffTheRimOrAgainstItsNormalStayOut) {
  const Ellipse truth = tilted();
  Rim rim = rimOf(truth, 200);
  // Clutter: points 1 px outside the rim, and points on it whose gradient runs along it.
  for (int i = 0; i < 20; ++i) {
    const Eigen::Vector2d p = pointAt(truth, 0.3 * i);
    const Eigen::Vector2d n = outwardNormal(truth, p);
    rim.points.push_back(p + 1.0 * n);
    rim.normals.push_back(n);
    rim.points.push_back(p);
    rim.normals.push_back({-n.y(), n.x()});
  }
  const std::vector<Eigen::Vector2d> seed(rim.points.begin(), rim.points.begin() + 120);
  const auto fit = fitRimEllipse(rim.points, rim.normals, seed, 0.5, std::cos(12 * kPi / 180));
  ASSERT_TRUE(fit);
  EXPECT_EQ(fit->inliers.size(), 200u);
  EXPECT_NEAR(fit->ellipse.centre.x(), truth.centre.x(), 0.01);
  EXPECT_NEAR(fit->ellipse.centre.y(), truth.centre.y(), 0.01);
}

TEST(RimEllipse, DegeneratePointsGiveNoEllipse) {
  // Collinear points, one point repeated, too few points, a hyperbola's branch: no ellipse, and
  // nothing that is not a number.
  std::vector<Eigen::Vector2d> line, same, few, hyperbola, normals;
  for (int i = 0; i < 40; ++i) {
    line.emplace_back(10.0 + i, 20.0 + 0.5 * i);
    same.emplace_back(33.3, 44.4);
    const double t = -1.0 + i / 20.0;
    hyperbola.emplace_back(50.0 + 10.0 * std::cosh(t), 50.0 + 10.0 * std::sinh(t));
    normals.emplace_back(1.0, 0.0);
  }
  few.assign(line.begin(), line.begin() + 5);
  const double cosTol = std::cos(12 * kPi / 180);
  EXPECT_FALSE(fitRimEllipse(line, normals, line, 0.5, cosTol));
  EXPECT_FALSE(fitRimEllipse(same, normals, same, 0.5, cosTol));
  EXPECT_FALSE(fitRimEllipse(few, normals, few, 0.5, cosTol));
  const auto h = fitRimEllipse(hyperbola, normals, hyperbola, 0.5, cosTol);
  if (h) {  // the best ellipse through a hyperbola's branch, if any, is a finite one
    EXPECT_TRUE(std::isfinite(h->ellipse.major) && std::isfinite(h->ellipse.minor));
    EXPECT_GE(h->ellipse.major, h->ellipse.minor);
  }
  EXPECT_EQ(secondHarmonicChiSquare(few, {{0, 0}, 1.0}), 0.0);
}

TEST(RimEllipse, TheSecondHarmonicTellsAnEllipseFromACircle) {
  // A round rim with noise: the statistic stays within chance (27.6 is exceeded once in a
  // million); the same rim 0.2 px elliptic (axes 30.1 and 29.9) is far beyond it.
  const Ellipse round{{100.3, 90.8}, 30.0, 30.0, {1.0, 0.0}};
  const Ellipse oval{{100.3, 90.8}, 30.1, 29.9, {1.0, 0.0}};
  const circle_fit::Circle circle{{100.3, 90.8}, 30.0};
  EXPECT_LT(secondHarmonicChiSquare(rimOf(round, 180).points, circle), 27.6);
  EXPECT_GT(secondHarmonicChiSquare(rimOf(oval, 180).points, circle), 100.0);
}

TEST(RimEllipse, ReshapingComposesWithTheMapAndItsStretchUndoesIt) {
  // A circle reshaped by (a, c) has exactly that stretch; an ellipse reshaped by minus its own
  // stretch is the circle of its area, about the same centre.
  const Ellipse circle{{50.5, 60.25}, 20.0, 20.0, {1.0, 0.0}};
  const Ellipse e = reshaped(circle, 0.03, -0.02);
  const cv::Vec2d v = stretchOf(e);
  EXPECT_NEAR(v[0], 0.03, 1e-12);
  EXPECT_NEAR(v[1], -0.02, 1e-12);
  EXPECT_NEAR(e.meanRadius(), 20.0, 1e-12);
  EXPECT_GT(e.major, e.minor);
  const Ellipse t = tilted();
  const cv::Vec2d s = stretchOf(t);
  const Ellipse back = reshaped(t, -s[0], -s[1]);
  EXPECT_NEAR(back.major, t.meanRadius(), 1e-9);
  EXPECT_NEAR(back.minor, t.meanRadius(), 1e-9);
  EXPECT_EQ(back.centre, t.centre);
  // Reshaping by nothing changes nothing.
  const Ellipse same = reshaped(t, 0.0, 0.0);
  EXPECT_NEAR(same.major, 30.0, 1e-9);
  EXPECT_NEAR(same.minor, 27.0, 1e-9);
  EXPECT_NEAR(std::abs(same.axis.dot(t.axis)), 1.0, 1e-12);
}

TEST(RimEllipse, TheConsensusOfSampledEllipsesKeepsTheRimBesideABorderAndClutter) {
  // 70% of the rim visible (what an occluding strip leaves), the strip's straight border with
  // gradients pointing away from the centre, clutter points scattered over the annulus: the
  // consensus holds the visible rim and nothing else.
  const Ellipse truth = tilted();
  Rim rim;
  {
    const Rim whole = rimOf(truth, 360);
    for (std::size_t i = 0; i < whole.points.size(); ++i)
      if (i < 252) {
        rim.points.push_back(whole.points[i]);
        rim.normals.push_back(whole.normals[i]);
      }
  }
  const std::size_t onRim = rim.points.size();
  const Eigen::Vector2d along = truth.axis, across{-truth.axis.y(), truth.axis.x()};
  for (int i = -20; i <= 20; ++i) {  // the border, 24 px from the centre
    rim.points.push_back(truth.centre - 24.0 * along + 0.7 * i * across);
    rim.normals.push_back(-along);
  }
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  for (int i = 0; i < 60; ++i) {
    const double a = 2 * kPi * u(rng), r = 22.0 + 12.0 * u(rng), g = 2 * kPi * u(rng);
    rim.points.push_back(truth.centre + r * Eigen::Vector2d(std::cos(a), std::sin(a)));
    rim.normals.emplace_back(std::cos(g), std::sin(g));
  }
  const auto consensus = ellipseConsensus(rim.points, rim.normals, 0.5, std::cos(12 * kPi / 180));
  std::size_t fromRim = 0, other = 0;
  for (const auto& p : consensus) {
    const auto it = std::find(rim.points.begin(), rim.points.end(), p);
    (static_cast<std::size_t>(it - rim.points.begin()) < onRim ? fromRim : other) += 1;
  }
  EXPECT_GE(fromRim, onRim * 95 / 100);
  EXPECT_LE(other, 3u);  // a clutter point can fall within 0.5 px of the rim by chance
  const auto fit = fitRimEllipse(rim.points, rim.normals, consensus, 0.5, std::cos(12 * kPi / 180));
  ASSERT_TRUE(fit);
  EXPECT_NEAR(fit->ellipse.centre.x(), truth.centre.x(), 0.02);
  EXPECT_NEAR(fit->ellipse.centre.y(), truth.centre.y(), 0.02);
  EXPECT_NEAR(fit->ellipse.major, 30.0, 0.02);
  EXPECT_NEAR(fit->ellipse.minor, 27.0, 0.02);
}

}  // namespace
}  // namespace facet::rim_ellipse
