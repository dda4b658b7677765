// The propagated uncertainty of a fitted transform against the spread of many noisy fits.
#include <cmath>
#include <random>
#include <vector>

#include <gtest/gtest.h>
#include <opencv2/calib3d.hpp>

#include "algorithms/geometry/projective_map.hpp"
#include "algorithms/registration/homography_uncertainty.hpp"

namespace facet {
namespace {

const std::vector<cv::Point2d> kCorners = {{0, 0}, {399, 0}, {399, 299}, {0, 299}};

// Pairs on a 6 x 5 grid inside [x0, x1] x [y0, y1] of a 400 x 300 view.
std::vector<cv::Point2d> gridIn(double x0, double x1, double y0, double y1) {
  std::vector<cv::Point2d> p;
  for (int i = 0; i < 6; ++i)
    for (int j = 0; j < 5; ++j) p.emplace_back(x0 + (x1 - x0) * i / 5, y0 + (y1 - y0) * j / 4);
  return p;
}

// The least-squares fit of a similarity [a b tx; -b a ty] or an affine map (linear in their
// parameters, so least squares is the maximum-likelihood fit the propagation describes).
cv::Matx33d fitLinear(TransformModel model, const std::vector<cv::Point2d>& src,
                      const std::vector<cv::Point2d>& dst) {
  const int n = model == TransformModel::Similarity ? 4 : 6;
  cv::Mat A = cv::Mat::zeros(2 * static_cast<int>(src.size()), n, CV_64F), b(A.rows, 1, CV_64F);
  for (std::size_t i = 0; i < src.size(); ++i) {
    double* u = A.ptr<double>(2 * static_cast<int>(i));
    double* v = A.ptr<double>(2 * static_cast<int>(i) + 1);
    const cv::Point2d p = src[i];
    if (model == TransformModel::Similarity) {
      u[0] = p.x, u[1] = p.y, u[2] = 1;
      v[0] = p.y, v[1] = -p.x, v[3] = 1;
    } else {
      u[0] = p.x, u[1] = p.y, u[2] = 1;
      v[3] = p.x, v[4] = p.y, v[5] = 1;
    }
    b.at<double>(2 * static_cast<int>(i)) = dst[i].x;
    b.at<double>(2 * static_cast<int>(i) + 1) = dst[i].y;
  }
  cv::Mat x;
  cv::solve(A, b, x, cv::DECOMP_SVD);
  const double* k = x.ptr<double>();
  if (model == TransformModel::Similarity) return {k[0], k[1], k[2], -k[1], k[0], k[3], 0, 0, 1};
  return {k[0], k[1], k[2], k[3], k[4], k[5], 0, 0, 1};
}

cv::Matx33d fit(TransformModel model, const std::vector<cv::Point2d>& src,
                const std::vector<cv::Point2d>& dst) {
  if (model != TransformModel::Homography) return fitLinear(model, src, dst);
  // All pairs, then Levenberg-Marquardt on the transfer errors (OpenCV's method 0).
  cv::Mat H = cv::findHomography(src, dst, 0);
  return cv::Matx33d(H) * (1.0 / H.at<double>(2, 2));
}

// The worst standard deviation, over the corners, of where many fits to noisy pairs put them.
double spreadOfFits(TransformModel model, const cv::Matx33d& truth,
                    const std::vector<cv::Point2d>& src, double noise, int trials) {
  std::mt19937 rng(11);
  std::normal_distribution<double> n(0, noise);
  std::vector<cv::Matx22d> second(kCorners.size(), cv::Matx22d::zeros());
  std::vector<cv::Point2d> first(kCorners.size());
  for (int t = 0; t < trials; ++t) {
    std::vector<cv::Point2d> dst;
    for (const cv::Point2d& p : src)
      dst.push_back(mapPoint(truth, p) + cv::Point2d(n(rng), n(rng)));
    const cv::Matx33d H = fit(model, src, dst);
    for (std::size_t c = 0; c < kCorners.size(); ++c) {
      const cv::Point2d d = mapPoint(H, kCorners[c]) - mapPoint(truth, kCorners[c]);
      first[c] += d;
      second[c] += cv::Matx22d(d.x * d.x, d.x * d.y, d.x * d.y, d.y * d.y);
    }
  }
  double worst = 0;
  for (std::size_t c = 0; c < kCorners.size(); ++c) {
    const cv::Point2d m = first[c] * (1.0 / trials);
    const cv::Matx22d C =
        second[c] * (1.0 / trials) - cv::Matx22d(m.x * m.x, m.x * m.y, m.x * m.y, m.y * m.y);
    const double largest =
        0.5 * (C(0, 0) + C(1, 1)) + std::hypot(0.5 * (C(0, 0) - C(1, 1)), C(0, 1));
    worst = std::max(worst, std::sqrt(largest));
  }
  return worst;
}

TEST(HomographyUncertainty, AgreesWithTheSpreadOfManyNoisyFits) {
  const cv::Matx33d similarity(0.9 * std::cos(0.3), 0.9 * std::sin(0.3), 40, -0.9 * std::sin(0.3),
                               0.9 * std::cos(0.3), 60, 0, 0, 1);
  const cv::Matx33d affine(0.95, 0.12, 30, -0.08, 0.85, 50, 0, 0, 1);
  const cv::Matx33d homography(0.95, 0.12, 30, -0.08, 0.85, 50, 3e-4, -2e-4, 1);
  const double noise = 0.5;
  for (const auto& [model, truth] : {std::pair{TransformModel::Similarity, similarity},
                                     std::pair{TransformModel::Affine, affine},
                                     std::pair{TransformModel::Homography, homography}}) {
    // Spread over the view, and crowded into a quarter of it.
    for (const auto& src : {gridIn(20, 380, 20, 280), gridIn(20, 180, 20, 130)}) {
      std::vector<cv::Point2d> dst;
      for (const cv::Point2d& p : src) dst.push_back(mapPoint(truth, p));
      const double predicted = mappedPointUncertainty(model, truth, src, dst, noise, kCorners);
      const double measured = spreadOfFits(model, truth, src, noise, 2000);
      EXPECT_NEAR(predicted / measured, 1.0, 0.1)
          << static_cast<int>(model) << ": predicted " << predicted << ", measured " << measured;
    }
  }
}

TEST(HomographyUncertainty, PairsOnAStripLeaveTheFarCornersUncertain) {
  const cv::Matx33d truth(0.95, 0.12, 30, -0.08, 0.85, 50, 3e-4, -2e-4, 1);
  const auto spread = gridIn(20, 380, 20, 280), strip = gridIn(20, 380, 200, 230);
  auto uncertainty = [&](const std::vector<cv::Point2d>& src) {
    std::vector<cv::Point2d> dst;
    for (const cv::Point2d& p : src) dst.push_back(mapPoint(truth, p));
    return mappedPointUncertainty(TransformModel::Homography, truth, src, dst, 0.1, kCorners);
  };
  EXPECT_LT(uncertainty(spread), 0.1);
  EXPECT_GT(uncertainty(strip), 10 * uncertainty(spread));
}

TEST(HomographyUncertainty, PairsThatDoNotFixTheTransformGiveInfinity) {
  const cv::Matx33d truth = cv::Matx33d::eye();
  std::vector<cv::Point2d> line;  // all on one line: nothing fixes the scale across it
  for (int i = 0; i < 10; ++i) line.emplace_back(20 + 30 * i, 40 + 10 * i);
  for (TransformModel model : {TransformModel::Affine, TransformModel::Homography})
    EXPECT_TRUE(std::isinf(mappedPointUncertainty(model, truth, line, line, 0.1, kCorners)));
  const std::vector<cv::Point2d> three = {{0, 0}, {100, 0}, {0, 100}};
  EXPECT_TRUE(std::isinf(
      mappedPointUncertainty(TransformModel::Homography, truth, three, three, 0.1, kCorners)));
}

TEST(HomographyUncertainty, NeighboursSharingTheirErrorsWeighAsFewer) {
  // Pairs 10 px apart; within 15 px each has up to 8 others (fewer on the border).
  std::vector<cv::Point2d> src;
  for (int i = 0; i < 20; ++i)
    for (int j = 0; j < 20; ++j) src.emplace_back(10.0 * i, 10.0 * j);
  double neighbours = 0;
  for (const cv::Point2d& p : src)
    for (const cv::Point2d& q : src) neighbours += (p != q && cv::norm(p - q) <= 15.0);
  neighbours /= static_cast<double>(src.size());
  // Errors of their own: no more weight than their number says.
  std::mt19937 rng(3);
  std::normal_distribution<double> n(0, 0.3);
  std::vector<cv::Point2d> own;
  for (std::size_t k = 0; k < src.size(); ++k) own.emplace_back(n(rng), n(rng));
  EXPECT_NEAR(sharedErrorFactor(src, own, 15.0), 1.0, 0.3);
  // One error shared by all (a field no transform of the family follows): each pair's
  // neighbourhood counts as one.
  const std::vector<cv::Point2d> shared(src.size(), cv::Point2d(0.2, -0.1));
  EXPECT_NEAR(sharedErrorFactor(src, shared, 15.0), 1.0 + neighbours, 1e-9);
  // Neighbours' errors opposed: never below 1.
  std::vector<cv::Point2d> alternating;
  for (int i = 0; i < 20; ++i)
    for (int j = 0; j < 20; ++j) alternating.emplace_back((i + j) % 2 ? 0.2 : -0.2, 0);
  EXPECT_GE(sharedErrorFactor(src, alternating, 15.0), 1.0);
}

}  // namespace
}  // namespace facet
