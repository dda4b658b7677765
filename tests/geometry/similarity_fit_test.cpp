// The shared similarity fit, point mapping and Levenberg-Marquardt loop against known answers.
#include <gtest/gtest.h>

#include <random>

#include "algorithms/geometry/levenberg_marquardt.hpp"
#include "algorithms/geometry/pose2d.hpp"
#include "algorithms/geometry/projective_map.hpp"
#include "algorithms/geometry/similarity_fit.hpp"

namespace facet {
namespace {

// Points carried by a known pose (project convention) give back that pose's angle and scale,
// and the fitted map carries every point where the pose does, through mapPoint.
TEST(SimilarityFit, RecoversAKnownPoseInTheProjectsConvention) {
  const Pose2D pose{12.5, -4.0, radians(33.0), 1.7};
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> u(-50.0, 50.0);
  std::vector<cv::Point2d> from, to;
  for (int i = 0; i < 6; ++i) {
    from.emplace_back(u(rng), u(rng));
    to.push_back(pose.apply(from.back()));
  }
  const auto fit = fitSimilarity(from, to);
  ASSERT_TRUE(fit);
  EXPECT_NEAR(fit->rotationDeg, 33.0, 1e-9);
  EXPECT_NEAR(fit->scale, 1.7, 1e-12);
  for (std::size_t i = 0; i < from.size(); ++i) {
    const cv::Point2d q = mapPoint(fit->H, from[i]);
    EXPECT_NEAR(q.x, to[i].x, 1e-9);
    EXPECT_NEAR(q.y, to[i].y, 1e-9);
  }
}

TEST(SimilarityFit, CoincidentOrTooFewPointsGiveNothing) {
  EXPECT_FALSE(fitSimilarity({{1, 1}, {1, 1}}, {{0, 0}, {3, 4}}));
  EXPECT_FALSE(fitSimilarity({{1, 1}}, {{0, 0}}));
}

TEST(ProjectiveMap, DividesByTheProjectiveCoordinate) {
  const cv::Matx33d H{2, 0, 1, 0, 3, -1, 0.5, 0, 1};
  const cv::Point2d q = mapPoint(H, {2, 1});  // (5, 2) / 2
  EXPECT_DOUBLE_EQ(q.x, 2.5);
  EXPECT_DOUBLE_EQ(q.y, 1.0);
}

// y = a exp(b t) through noise-free samples: the loop lands on (a, b) from a poor start.
struct ExponentialFit {
  std::vector<double> t, y;
  double cost(const Eigen::Vector2d& x) const {
    double c = 0;
    for (std::size_t i = 0; i < t.size(); ++i) {
      const double r = x(0) * std::exp(x(1) * t[i]) - y[i];
      c += r * r;
    }
    return c;
  }
  void normalEquations(int, const Eigen::Vector2d& x, Eigen::Matrix2d& jtj, Eigen::Vector2d& jtr,
                       double&) const {
    jtj.setZero();
    jtr.setZero();
    for (std::size_t i = 0; i < t.size(); ++i) {
      const double e = std::exp(x(1) * t[i]);
      const Eigen::Vector2d j{e, x(0) * t[i] * e};
      jtj += j * j.transpose();
      jtr += j * (x(0) * e - y[i]);
    }
  }
  std::optional<double> trialCost(const Eigen::Vector2d& x) const { return cost(x); }
  void accept() {}
  bool converged(int, const Eigen::Vector2d& step) const { return step.norm() < 1e-12; }
};

TEST(LevenbergMarquardt, FitsAnExponentialFromAPoorStart) {
  ExponentialFit problem;
  for (int i = 0; i <= 20; ++i) {
    problem.t.push_back(0.1 * i);
    problem.y.push_back(2.5 * std::exp(-1.3 * 0.1 * i));
  }
  Eigen::Vector2d x{1.0, 0.0};
  const auto stop = levenbergMarquardt(problem, x, {.maxIterations = 100});
  EXPECT_NE(stop, LevenbergMarquardtStop::NonFiniteStep);
  EXPECT_NEAR(x(0), 2.5, 1e-8);
  EXPECT_NEAR(x(1), -1.3, 1e-8);
}

}  // namespace
}  // namespace facet
