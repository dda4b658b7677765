// fitHomographyCauchy on pairs with known truth: wrong pairs, and a view a homography cannot fit
// exactly (a lens's distortion), where the fit must spread over the whole view.
#include <cmath>
#include <random>
#include <vector>

#include <gtest/gtest.h>
#include <opencv2/calib3d.hpp>

#include "algorithms/geometry/projective_map.hpp"
#include "algorithms/registration/robust_homography.hpp"
#include "algorithms/registration/transform_fit.hpp"

namespace facet {
namespace {

const cv::Size kView(800, 600);
const cv::Matx33d kTruth(0.52, 0.21, 160.0, -0.19, 0.55, 190.0, 2e-5, -1e-5, 1.0);

double cornerError(const cv::Matx33d& est, const cv::Matx33d& truth) {
  const cv::Point2d corners[4] = {{0, 0},
                                  {kView.width - 1.0, 0},
                                  {kView.width - 1.0, kView.height - 1.0},
                                  {0, kView.height - 1.0}};
  double sum = 0;
  for (const auto& c : corners) {
    const cv::Point2d a = mapPoint(est, c), b = mapPoint(truth, c);
    sum += std::hypot(a.x - b.x, a.y - b.y);
  }
  return sum / 4;
}

// Pairs on a 20 px grid over the view, mapped by truth, then bent radially about the image's
// centre by `bend` px at its farthest (a lens the homography cannot follow) and given Gaussian
// noise of `noise` px.
void gridPairs(double bend, double noise, std::vector<cv::Point2d>& src,
               std::vector<cv::Point2d>& dst, std::mt19937& rng) {
  std::normal_distribution<double> gauss(0.0, noise);
  const cv::Point2d centre = mapPoint(kTruth, {kView.width / 2.0, kView.height / 2.0});
  const double reach = 260;  // about the farthest image distance of a mapped corner
  for (int y = 10; y < kView.height; y += 20)
    for (int x = 10; x < kView.width; x += 20) {
      const cv::Point2d p(x, y);
      cv::Point2d q = mapPoint(kTruth, p);
      const cv::Point2d d = q - centre;
      const double r = std::hypot(d.x, d.y) / reach;
      q += d * (bend * r * r / reach);
      src.push_back(p);
      dst.push_back(q + cv::Point2d(gauss(rng), gauss(rng)));
    }
}

TEST(FitHomographyCauchy, WrongPairsDoNotPullTheFit) {
  std::mt19937 rng(3);
  std::vector<cv::Point2d> src, dst;
  gridPairs(0.0, 0.1, src, dst, rng);
  // A quarter of the pairs wrong by 1.5-3 px: within any inlier threshold, so only the loss
  // can keep them from the fit.
  std::uniform_real_distribution<double> off(1.5, 3.0), turn(0, 2 * CV_PI);
  for (std::size_t i = 0; i < dst.size(); i += 4) {
    const double a = turn(rng), d = off(rng);
    dst[i] += cv::Point2d(d * std::cos(a), d * std::sin(a));
  }
  const auto fit = fitHomographyCauchy(src, dst, kTruth);
  ASSERT_TRUE(fit);
  const auto leastSquares = fitTransformLeastSquares(src, dst, TransformModel::Homography);
  ASSERT_TRUE(leastSquares);
  EXPECT_LT(cornerError(fit->H, kTruth), 0.05);
  EXPECT_GT(cornerError(*leastSquares, kTruth), 2 * cornerError(fit->H, kTruth));
  EXPECT_NEAR(fit->noise, 0.1, 0.03);
}

TEST(FitHomographyCauchy, ALensTheHomographyCannotFollowIsFittedOverTheWholeView) {
  std::mt19937 rng(5);
  std::vector<cv::Point2d> src, dst;
  gridPairs(1.5, 0.05, src, dst, rng);
  // The reference: least squares (Levenberg-Marquardt on the transfer error) on every pair.
  std::vector<cv::Point2f> s(src.begin(), src.end()), d(dst.begin(), dst.end());
  const cv::Matx33d whole(cv::findHomography(s, d, 0));
  // Least squares on the pairs within 0.5 px of the truth: the part of the view the start fits.
  std::vector<cv::Point2f> ns, nd;
  for (std::size_t i = 0; i < src.size(); ++i)
    if (transferError(kTruth, src[i], dst[i]) <= 0.5) {
      ns.emplace_back(src[i]);
      nd.emplace_back(dst[i]);
    }
  ASSERT_GT(ns.size(), 8u);
  ASSERT_LT(ns.size(), src.size() * 9 / 10);
  const cv::Matx33d part(cv::findHomography(ns, nd, 0));
  const auto fit = fitHomographyCauchy(src, dst, kTruth);
  ASSERT_TRUE(fit);
  EXPECT_LT(cornerError(fit->H, whole), 0.5 * cornerError(part, whole));
}

// Pairs located sharply in one direction and loosely in the other (edges at random angles):
// 0.02 px across, 0.5 px along.
void edgePairs(std::vector<cv::Point2d>& src, std::vector<cv::Point2d>& dst,
               std::vector<cv::Matx22d>& sharpness, std::mt19937& rng) {
  std::normal_distribution<double> unit(0.0, 1.0);
  std::uniform_real_distribution<double> turn(0, CV_PI);
  const double across = 0.02, along = 0.5;
  for (int y = 10; y < kView.height; y += 20)
    for (int x = 10; x < kView.width; x += 20) {
      const double a = turn(rng);
      const cv::Point2d u(std::cos(a), std::sin(a)), n(-u.y, u.x);
      src.emplace_back(x, y);
      dst.push_back(mapPoint(kTruth, {double(x), double(y)}) + u * (along * unit(rng)) +
                    n * (across * unit(rng)));
      const cv::Matx21d U(u.x, u.y), N(n.x, n.y);
      sharpness.push_back(U * U.t() * (1 / (along * along)) + N * N.t() * (1 / (across * across)));
    }
}

TEST(FitHomographyCauchy, EachPairCountsInTheDirectionItIsLocatedIn) {
  std::mt19937 rng(7);
  std::vector<cv::Point2d> src, dst;
  std::vector<cv::Matx22d> sharpness;
  edgePairs(src, dst, sharpness, rng);
  const auto plain = fitHomographyCauchy(src, dst, kTruth);
  const auto shaped = fitHomographyCauchy(src, dst, kTruth, sharpness);
  ASSERT_TRUE(plain && shaped);
  EXPECT_LT(cornerError(shaped->H, kTruth), cornerError(plain->H, kTruth) / 3);
  // The noise is reported in pixels whatever the metric the pairs were weighed in.
  EXPECT_NEAR(shaped->noise, plain->noise, 0.2 * plain->noise);
}

TEST(FitHomographyCauchy, AnErrorAllPairsShareOutweighsTheirSharpness) {
  // The bent lens again, the pairs now with sharpness, sharp on the left third of the view
  // (where the texture is) and loose elsewhere: what no homography follows is the same for all
  // of them and much larger than their location's noise, so they must count about equally, as
  // without sharpness, and not by how sharp their peaks are (the fit would lean to the left).
  std::mt19937 rng(5);
  std::vector<cv::Point2d> src, dst;
  gridPairs(1.5, 0.05, src, dst, rng);
  std::vector<cv::Matx22d> sharpness;
  for (const cv::Point2d& p : src)
    sharpness.push_back(cv::Matx22d::eye() * (p.x < kView.width / 3 ? 400.0 : 1.0));
  std::vector<cv::Point2f> s(src.begin(), src.end()), d(dst.begin(), dst.end());
  const cv::Matx33d whole(cv::findHomography(s, d, 0));
  const auto plain = fitHomographyCauchy(src, dst, kTruth);
  const auto shaped = fitHomographyCauchy(src, dst, kTruth, sharpness);
  ASSERT_TRUE(plain && shaped);
  EXPECT_LT(cornerError(shaped->H, whole), 1.2 * cornerError(plain->H, whole) + 0.01);
}

TEST(FitHomographyCauchy, TooFewPairsGiveNoFit) {
  std::vector<cv::Point2d> src{{0, 0}, {10, 0}, {0, 10}, {10, 10}, {5, 5}};
  EXPECT_FALSE(fitHomographyCauchy(src, src, cv::Matx33d::eye()));
}

}  // namespace
}  // namespace facet
