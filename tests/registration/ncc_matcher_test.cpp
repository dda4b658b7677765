// Log-polar windows and their NCC: shifts mean rotation/scale, accelerations change nothing.
#include <algorithm>
#include <cmath>

#include <thread>
#include <utility>
#include <vector>

#include <gtest/gtest.h>
#include <opencv2/imgproc.hpp>

#include "algorithms/registration/harris_corners.hpp"
#include "algorithms/registration/log_polar_window.hpp"
#include "algorithms/registration/ncc_matcher.hpp"
#include "tests/registration/textured_scene.hpp"
#include "tests/support/scene/plane_scene.hpp"

namespace facet {
namespace {

cv::Mat toFloat(const cv::Mat& img) {
  cv::Mat f;
  img.convertTo(f, CV_32F, 1 / 255.0);
  return f;
}

TEST(LogPolarWindow, ShiftCorrespondsToRotationAndScale) {
  const cv::Mat ref = testing::texturedScene({300, 300}, 17);
  const cv::Point2d c(150, 150);
  LogPolarParams lp;  // 32 angles (11.25 deg), ring ratio 1.19
  const auto refPyramid = buildSamplingPyramid(toFloat(ref));
  const LogPolarWindow a = sampleLogPolar(refPyramid, c, cv::Matx22d(6, 0, 0, 6), lp);
  ASSERT_TRUE(a.valid);
  for (const auto& [angleSteps, ringSteps] :
       {std::pair{4, 1}, std::pair{-7, 0}, std::pair{12, -1}}) {
    // Image = reference turned by angleSteps * 11.25 deg about c (in the window's angle sense,
    // x towards y) and scaled by 1.19^ringSteps.
    const double phi = angleSteps * 2 * CV_PI / lp.angles, s = std::pow(lp.ringRatio, ringSteps);
    const cv::Matx22d L(s * std::cos(phi), -s * std::sin(phi), s * std::sin(phi),
                        s * std::cos(phi));
    const cv::Matx33d H(L(0, 0), L(0, 1), c.x - L(0, 0) * c.x - L(0, 1) * c.y, L(1, 0), L(1, 1),
                        c.y - L(1, 0) * c.x - L(1, 1) * c.y, 0, 0, 1);
    const cv::Mat image = testing::warp(ref, H, ref.size());
    const LogPolarWindow b =
        sampleLogPolar(buildSamplingPyramid(toFloat(image)), c, cv::Matx22d(6, 0, 0, 6), lp);
    ASSERT_TRUE(b.valid);
    const WindowScore w = compareWindows(a, b, lp.ringShifts, 0.0, {});
    EXPECT_EQ(w.angleShift, (angleSteps + lp.angles) % lp.angles) << angleSteps;
    EXPECT_EQ(w.ringShift, ringSteps);
    EXPECT_GT(w.score, 0.9);
  }
}

// Windows from a textured scene and from a rotated, scaled, noisy copy: some pairs match well,
// most do not, which exercises every pruning path.
std::pair<std::vector<LogPolarWindow>, std::vector<LogPolarWindow>> windowSets(int count) {
  const cv::Mat ref = testing::texturedScene({320, 320}, 29);
  const cv::Matx33d H = testing::similarity(70.0, 1.15, {159.5, 159.5}, {159.5, 159.5});
  cv::Mat image = testing::warp(ref, H, ref.size());
  cv::Mat noise(image.size(), CV_8U);
  cv::randn(noise, 0, 4);
  image += noise;
  LogPolarParams lp;
  HarrisParams hp;
  hp.maxCorners = count;
  auto windows = [&](const cv::Mat& img) {
    const cv::Mat f = toFloat(img);
    const auto pyramid = buildSamplingPyramid(f);
    std::vector<LogPolarWindow> out;
    for (const auto& c : detectHarrisCorners(f, hp)) {
      LogPolarWindow w = sampleLogPolar(pyramid, c.pt, cv::Matx22d(c.scale, 0, 0, c.scale), lp);
      if (w.valid) out.push_back(std::move(w));
    }
    // Random windows at random points too (not corners).
    cv::RNG rng(3);
    for (int i = 0; i < count / 4; ++i) {
      const cv::Point2d p(rng.uniform(60.0, 260.0), rng.uniform(60.0, 260.0));
      const double s = rng.uniform(1.5, 4.0);
      LogPolarWindow w = sampleLogPolar(pyramid, p, cv::Matx22d(s, 0, 0, s), lp);
      if (w.valid) out.push_back(std::move(w));
    }
    return out;
  };
  return {windows(ref), windows(image)};
}

TEST(NccMatcher, AccelerationsGiveIdenticalScoresToPlainNcc) {
  const auto [a, b] = windowSets(40);
  ASSERT_GT(a.size(), 30u);
  ASSERT_GT(b.size(), 30u);
  int compared = 0, aboveThreshold = 0;
  for (std::size_t i = 0; i < a.size(); i += 3)
    for (std::size_t j = 0; j < b.size(); j += 2) {
      for (double threshold : {-1.0, 0.5, 0.8}) {
        const WindowScore plain = compareWindows(a[i], b[j], 2, threshold, {false, false, false});
        aboveThreshold += plain.score >= threshold;
        for (int flags = 1; flags < 8; ++flags) {
          const NccAccelerations acc{(flags & 1) != 0, (flags & 2) != 0, (flags & 4) != 0};
          const WindowScore fast = compareWindows(a[i], b[j], 2, threshold, acc);
          ASSERT_EQ(fast.score, plain.score) << i << " " << j << " flags " << flags;
          ASSERT_EQ(fast.ringShift, plain.ringShift);
          ASSERT_EQ(fast.angleShift, plain.angleShift);
        }
        ++compared;
      }
    }
  EXPECT_GT(compared, 500);
  EXPECT_GT(aboveThreshold, 50);  // the comparison covered accepted pairs, not just rejections
}

TEST(NccMatcher, AcceleratedMatchingGivesTheSameMatches) {
  const auto [a, b] = windowSets(80);
  NccMatchParams plainParams;
  plainParams.accelerations = {false, false, false};
  const auto plain = matchWindows(a, b, 2, plainParams);
  EXPECT_GT(plain.size(), 20u);
  for (int flags = 1; flags < 8; ++flags) {
    NccMatchParams p;
    p.accelerations = {(flags & 1) != 0, (flags & 2) != 0, (flags & 4) != 0};
    const auto fast = matchWindows(a, b, 2, p);
    ASSERT_EQ(fast.size(), plain.size()) << flags;
    for (std::size_t k = 0; k < plain.size(); ++k) {
      EXPECT_EQ(fast[k].ref, plain[k].ref);
      EXPECT_EQ(fast[k].image, plain[k].image);
      EXPECT_EQ(fast[k].best.score, plain[k].best.score);
    }
  }
}

TEST(NccMatcher, CandidatesAreTheBestFewOfEveryReferenceWindowBestFirst) {
  const auto [a, b] = windowSets(80);
  NccMatchParams p;
  p.candidates = 3;
  for (int flags : {0, 7}) {
    p.accelerations = {(flags & 1) != 0, (flags & 2) != 0, (flags & 4) != 0};
    const auto got = matchWindows(a, b, 2, p);
    std::size_t next = 0, withSeveral = 0;
    for (std::size_t i = 0; i < a.size(); ++i) {
      // Every image window's score, as the one-pair comparison gives it.
      std::vector<std::pair<double, int>> all;
      for (std::size_t j = 0; j < b.size(); ++j) {
        const WindowScore s = compareWindows(a[i], b[j], 2, p.minScore, p.accelerations);
        if (s.score >= p.minScore) all.emplace_back(s.score, static_cast<int>(j));
      }
      // Best first; ties keep the earlier image window.
      std::stable_sort(all.begin(), all.end(),
                       [](const auto& x, const auto& y) { return x.first > y.first; });
      const std::size_t expected = std::min<std::size_t>(all.size(), 3);
      withSeveral += expected > 1;
      for (std::size_t k = 0; k < expected; ++k, ++next) {
        ASSERT_LT(next, got.size()) << flags;
        EXPECT_EQ(got[next].ref, static_cast<int>(i)) << flags;
        EXPECT_EQ(got[next].image, all[k].second) << flags << " window " << i << " rank " << k;
        EXPECT_EQ(got[next].best.score, all[k].first) << flags;
      }
    }
    EXPECT_EQ(next, got.size()) << flags;
    EXPECT_GT(withSeveral, 5u) << flags;  // the test saw windows with more than one candidate
  }
}

// Registration's last two stages share one all-pairs pass: the look-alike stage's candidates,
// from which the plain escalation takes the best of each.
TEST(NccMatcher, TheBestOfEachWindowsCandidatesIsTheSingleCandidateMatching) {
  const auto [a, b] = windowSets(80);
  for (double minScore : {0.5, 0.7, 0.75}) {
    NccMatchParams single;
    single.minScore = minScore;
    const auto expected = matchWindows(a, b, 2, single);
    ASSERT_GT(expected.size(), 20u);
    for (int candidates : {2, 3, 5}) {
      NccMatchParams several = single;
      several.candidates = candidates;
      const auto listed = matchWindows(a, b, 2, several);
      const auto got = bestOfEach(listed);
      ASSERT_EQ(got.size(), expected.size()) << minScore << " " << candidates;
      for (std::size_t k = 0; k < expected.size(); ++k) {
        EXPECT_EQ(got[k].ref, expected[k].ref);
        EXPECT_EQ(got[k].image, expected[k].image);
        EXPECT_EQ(got[k].best.score, expected[k].best.score);
        EXPECT_EQ(got[k].best.ringShift, expected[k].best.ringShift);
        EXPECT_EQ(got[k].best.angleShift, expected[k].best.angleShift);
      }
      // The one-to-one rule had something to do: some image window was the best of two
      // reference windows.
      std::size_t refs = 0;
      for (std::size_t k = 0; k < listed.size(); ++k)
        refs += k == 0 || listed[k].ref != listed[k - 1].ref;
      EXPECT_LT(got.size(), refs) << minScore << " " << candidates;
    }
  }
}

TEST(HarrisCorners, BudgetAndSpreading) {
  const cv::Mat f = toFloat(testing::texturedScene({400, 300}, 2));
  HarrisParams hp;
  hp.maxCorners = 100;
  const auto corners = detectHarrisCorners(f, hp);
  EXPECT_EQ(corners.size(), 100u);
  // Spread: every quadrant of the image holds some corners.
  int quadrant[4] = {0, 0, 0, 0};
  for (const auto& c : corners) ++quadrant[(c.pt.x > 200) + 2 * (c.pt.y > 150)];
  for (int q : quadrant) EXPECT_GE(q, 10);
  // A flat image has none.
  EXPECT_TRUE(detectHarrisCorners(cv::Mat(100, 100, CV_32F, cv::Scalar(0.5)), hp).empty());
}

// A drawing of flat polygons behind a sharp lens (blur 0.7 px): where two straight edges meet
// the corner has no characteristic scale, and a strict maximum of the Laplacian over scales
// (scalePlateau 1) loses most vertices from the finest levels; the default keeps them there.
TEST(HarrisCorners, VerticesOfASharpDrawingAreFoundAtTheFinestScales) {
  const std::vector<std::vector<cv::Point2d>> polygons = {
      {{40.3, 50.2}, {150.7, 42.9}, {120.4, 140.6}},
      {{200.2, 40.6}, {330.8, 70.1}, {310.5, 160.3}, {190.9, 130.7}},
      {{80.6, 180.4}, {150.1, 170.2}, {170.7, 240.9}, {110.3, 270.5}, {60.2, 240.8}}};
  // Exact pixel coverage of each polygon, painted over a light background.
  cv::Mat f(300, 400, CV_64F, cv::Scalar(200));
  double shade = 40;
  for (const auto& poly : polygons) {
    f += scene::polygonCoverage(poly, f.size()) * (shade - 200);
    shade += 50;
  }
  f.convertTo(f, CV_32F, 1 / 255.0);
  cv::GaussianBlur(f, f, cv::Size(), 0.7, 0.7);
  auto verticesAtFinestLevels = [&](double plateau) {
    HarrisParams hp;
    hp.scalePlateau = plateau;
    const auto corners = detectHarrisCorners(f, hp);
    // A Harris corner lies inside the wedge, up to twice the integration scale (4 px) from the
    // vertex at the finest level.
    int found = 0, total = 0;
    for (const auto& poly : polygons)
      for (const auto& v : poly) {
        ++total;
        found += std::any_of(corners.begin(), corners.end(), [&](const HarrisCorner& c) {
          return c.level <= 1 && std::hypot(c.pt.x - v.x, c.pt.y - v.y) < 4.0;
        });
      }
    return std::pair(found, total);
  };
  const auto [found, total] = verticesAtFinestLevels(HarrisParams{}.scalePlateau);
  EXPECT_EQ(found, total);
  const auto [strictFound, strictTotal] = verticesAtFinestLevels(1.0);
  EXPECT_LE(strictFound, strictTotal / 2)
      << "the strict maximum now keeps the vertices: is the test "
         "still one of scale-free corners?";
}

// A 3000x2000 detection passes through more full-size images than a thread keeps: it keeps up to
// its limit, allocates the rest, and finds the same corners the next time, partly in kept
// buffers, as the first.
TEST(HarrisCorners, AThreadKeepsNoMoreThanItsLimitForALargeFrame) {
  const cv::Mat f = toFloat(testing::texturedScene({3000, 2000}, 4, 2000));
  std::size_t kept = 0;
  std::vector<HarrisCorner> first, second;
  std::thread([&] {
    first = detectHarrisCorners(f);
    kept = keptCornerImageBytes();
    second = detectHarrisCorners(f);
  }).join();
  EXPECT_GT(kept, kKeptImageBytes / 2);
  EXPECT_LE(kept, kKeptImageBytes);
  ASSERT_EQ(first.size(), second.size());
  for (std::size_t i = 0; i < first.size(); ++i) EXPECT_EQ(first[i].pt, second[i].pt);
}

}  // namespace
}  // namespace facet
