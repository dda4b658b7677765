// Subpixel edges on rendered scenes with exact ground truth: straight edges at several
// orientations, 16-bit input, ROI and mask, automatic thresholds, hysteresis, linking, the
// curvature correction and bad input.
#include <algorithm>
#include <cmath>
#include <numbers>
#include <stdexcept>
#include <string>

#include <gtest/gtest.h>
#include <opencv2/imgproc.hpp>

#include "algorithms/edges/auto_thresholds.hpp"
#include "algorithms/edges/canny.hpp"
#include "algorithms/edges/row_runs.hpp"
#include "algorithms/edges/subpixel_edges.hpp"
#include "tests/support/scene/scene.hpp"

namespace facet {
namespace {

using scene::Scene;
using scene::SceneSpec;

struct StraightEdge {
  cv::Mat image;
  cv::Point2d p0, n;  // a point on the edge and the unit normal (dark -> light)
};

// A half-plane edge through the image centre with normal angle `deg`, contrast 100.
StraightEdge straightEdge(double deg, double blur, double noise, int depth = CV_8U, int size = 96) {
  SceneSpec spec;
  spec.size = {size, size};
  spec.background = 40;
  spec.blurSigma = blur;
  spec.noiseSigma = noise;
  spec.depth = depth;
  spec.subrows = 64;
  spec.seed = 3 + static_cast<std::uint64_t>(deg);
  Scene scene(spec);
  const double a = deg * std::numbers::pi / 180;
  StraightEdge e;
  e.n = {std::cos(a), std::sin(a)};
  const cv::Point2d t{-e.n.y, e.n.x};
  e.p0 = {size / 2.0 + 0.29, size / 2.0 - 0.41};
  scene.addPolygon(
      {e.p0 + 400 * t, e.p0 + 400 * t + 400 * e.n, e.p0 - 400 * t + 400 * e.n, e.p0 - 400 * t},
      140);
  e.image = scene.render();
  return e;
}

struct Errors {
  double rms = 0;
  int count = 0;
};

Errors distanceErrors(const EdgeContours& edges, const StraightEdge& e, double margin) {
  Errors r;
  double sum = 0;
  for (const auto& p : edges.points) {
    if (p.position.x < margin || p.position.y < margin || p.position.x > e.image.cols - margin ||
        p.position.y > e.image.rows - margin)
      continue;
    const double d = (p.position - e.p0).dot(e.n);
    sum += d * d;
    ++r.count;
  }
  r.rms = r.count ? std::sqrt(sum / r.count) : 1e9;
  return r;
}

class StraightEdgeAccuracy : public ::testing::TestWithParam<double> {};

TEST_P(StraightEdgeAccuracy, NoiseFreeWithinOneHundredthPixel) {
  const StraightEdge e = straightEdge(GetParam(), 1.0, 0.0);
  EdgeParams params;
  params.low = 5;
  params.high = 10;
  const EdgeContours edges = detectSubpixelEdges(e.image, params);
  const Errors err = distanceErrors(edges, e, 10);
  EXPECT_GT(err.count, 60);
  EXPECT_LE(err.rms, 0.01) << "at " << GetParam() << " deg";
  for (const auto& p : edges.points) {
    EXPECT_NEAR(p.normal.dot(e.n), 1.0, 1e-3);
    EXPECT_NEAR(cv::norm(p.normal), 1.0, 1e-9);
  }
}

TEST_P(StraightEdgeAccuracy, NoiseSigmaTwoWithinThreeHundredthsPixel) {
  const StraightEdge e = straightEdge(GetParam(), 1.0, 2.0, CV_8U, 160);
  EdgeParams params;
  params.low = 5;
  params.high = 10;
  const Errors err = distanceErrors(detectSubpixelEdges(e.image, params), e, 12);
  EXPECT_GT(err.count, 100);
  EXPECT_LE(err.rms, 0.03) << "at " << GetParam() << " deg";
}

INSTANTIATE_TEST_SUITE_P(Orientations, StraightEdgeAccuracy,
                         ::testing::Values(0.0, 7.0, 30.0, 45.0, 62.0, 90.0, 133.0, 171.0));

// Points within the fit's window reach (about 9 px) of the image border: the window is cut to the
// image. The scene is rendered larger and cut out, so that it continues past the border as a
// camera's view does; the points near the border are then as precise as the interior's. With the
// full windows only (fitAtImageBorder = false) they keep the facet zero crossing, off by up to
// 0.15 px at a sharp lens.
TEST(SubpixelEdges, PointsNearTheImageBorderAreAsPreciseAsInside) {
  for (const scene::BlurModel model : {scene::BlurModel::Lens, scene::BlurModel::PixelGrid}) {
    for (const double deg : {2.0, 33.0, 88.0, 151.0}) {
      SceneSpec spec;
      spec.size = {96, 96};
      spec.background = 40;
      spec.blurSigma = 0.6;
      spec.blurModel = model;
      spec.subrows = 64;
      Scene scene(spec);
      const double a = deg * std::numbers::pi / 180;
      const cv::Point2d n{std::cos(a), std::sin(a)}, t{-n.y, n.x}, p0{48.29, 47.59};
      scene.addPolygon({p0 + 400 * t, p0 + 400 * t + 400 * n, p0 - 400 * t + 400 * n, p0 - 400 * t},
                       140);
      const cv::Rect cut(16, 16, 64, 64);  // the image: the scene's middle
      const cv::Mat image = scene.render()(cut).clone();
      const cv::Point2d q0 = p0 - cv::Point2d(cut.tl());
      const auto nearBorderErrors = [&](bool fitAtBorder, int& count) {
        EdgeParams params;
        params.low = 5;
        params.high = 10;
        params.fitAtImageBorder = fitAtBorder;
        double worst = 0;
        count = 0;
        for (const EdgePoint& p : detectSubpixelEdges(image, params).points) {
          const double border =
              std::min({p.position.x, p.position.y, 63 - p.position.x, 63 - p.position.y});
          if (border >= 10) continue;
          worst = std::max(worst, std::abs((p.position - q0).dot(n)));
          ++count;
        }
        return worst;
      };
      int cutCount = 0, fullCount = 0;
      const double cutWorst = nearBorderErrors(true, cutCount);
      const double fullWorst = nearBorderErrors(false, fullCount);
      const std::string where =
          std::string(scene::blurModelName(model)) + " " + std::to_string(deg) + " deg";
      EXPECT_GE(cutCount, 14) << where;  // both ends of the edge, 2-10 px from the border
      EXPECT_GE(cutCount, fullCount - 1) << where;
      EXPECT_LT(cutWorst, 0.01) << where;
      EXPECT_GT(fullWorst, 0.03) << where;
    }
  }
}

TEST(SubpixelEdges, OnePointPerRowOnA45DegreeEdge) {
  const StraightEdge e = straightEdge(45, 1.0, 0.0);
  EdgeParams params;
  params.low = 5;
  params.high = 10;
  const EdgeContours edges = detectSubpixelEdges(e.image, params);
  std::vector<int> perRow(e.image.rows, 0);
  for (const auto& p : edges.points) ++perRow[static_cast<int>(std::lround(p.position.y))];
  int rows = 0;
  for (int y = 8; y < e.image.rows - 8; ++y) {
    EXPECT_LE(perRow[y], 1) << "row " << y;
    rows += perRow[y] == 1;
  }
  EXPECT_GT(rows, e.image.rows - 24);  // and no gaps to speak of
}

TEST(SubpixelEdges, SixteenBitMatchesEightBit) {
  const StraightEdge e8 = straightEdge(23, 1.0, 0.0, CV_8U);
  const StraightEdge e16 = straightEdge(23, 1.0, 0.0, CV_16U);
  ASSERT_EQ(e16.image.type(), CV_16UC1);
  EdgeParams params;
  params.low = 5;
  params.high = 10;
  const EdgeContours a = detectSubpixelEdges(e8.image, params);
  const EdgeContours b = detectSubpixelEdges(e16.image, params);
  const Errors err = distanceErrors(b, e16, 10);
  EXPECT_GT(err.count, 60);
  EXPECT_LE(err.rms, 0.01);
  ASSERT_FALSE(a.points.empty());
  ASSERT_FALSE(b.points.empty());
  // Magnitudes are on the 8-bit scale for both: contrast 100 at blur 1 gives about 100 / (w
  // sqrt(2 pi)) with w ~ 1.04.
  EXPECT_NEAR(a.points[a.points.size() / 2].magnitude, 38.0, 3.0);
  EXPECT_NEAR(b.points[b.points.size() / 2].magnitude, 38.0, 3.0);
}

TEST(SubpixelEdges, RoiAndMaskRestrictThePoints) {
  SceneSpec spec;
  spec.size = {160, 120};
  spec.blurSigma = 1.0;
  Scene scene(spec);
  scene.addDisc({50.3, 60.2}, 25, 160);
  scene.addDisc({115.6, 58.9}, 25, 160);
  const cv::Mat image = scene.render();

  EdgeParams all;
  const EdgeContours full = detectSubpixelEdges(image, all);
  int left = 0, right = 0;
  for (const auto& p : full.points) (p.position.x < 80 ? left : right)++;
  EXPECT_GT(left, 100);
  EXPECT_GT(right, 100);

  EdgeParams roi;
  roi.roi = {0, 0, 80, 120};
  const EdgeContours inRoi = detectSubpixelEdges(image, roi);
  EXPECT_GT(inRoi.points.size(), 100u);
  for (const auto& p : inRoi.points) EXPECT_LT(p.position.x, 80.5);

  EdgeParams masked;
  masked.mask = cv::Mat::zeros(image.size(), CV_8U);
  cv::circle(masked.mask, {115, 59}, 35, 255, cv::FILLED);
  const EdgeContours inMask = detectSubpixelEdges(image, masked);
  EXPECT_GT(inMask.points.size(), 100u);
  for (const auto& p : inMask.points) {
    EXPECT_GT(p.position.x, 79);
    EXPECT_NEAR(cv::norm(p.position - cv::Point2d(115.6, 58.9)), 25.0, 0.3);
  }

  // A mask of the ROI's size covers the ROI: the same points as the image-sized mask, also
  // where the ROI reaches past the image's border.
  for (const cv::Rect box : {cv::Rect(70, 20, 80, 80), cv::Rect(100, -10, 80, 90)}) {
    EdgeParams imageMask, roiMask;
    imageMask.roi = roiMask.roi = box;
    imageMask.mask = masked.mask;
    roiMask.mask = cv::Mat::zeros(box.size(), CV_8U);
    cv::circle(roiMask.mask, cv::Point(115, 59) - box.tl(), 35, 255, cv::FILLED);
    const EdgeContours a = detectSubpixelEdges(image, imageMask);
    const EdgeContours b = detectSubpixelEdges(image, roiMask);
    EXPECT_GT(a.points.size(), 50u);
    ASSERT_EQ(a.points.size(), b.points.size());
    for (std::size_t i = 0; i < a.points.size(); ++i)
      EXPECT_EQ(a.points[i].position, b.points[i].position);
  }

  EdgeParams badMask;
  badMask.mask = cv::Mat::zeros(10, 10, CV_8U);
  EXPECT_THROW(detectSubpixelEdges(image, badMask), std::invalid_argument);
  badMask.roi = {0, 0, 20, 20};  // neither the image's nor the ROI's size
  EXPECT_THROW(detectSubpixelEdges(image, badMask), std::invalid_argument);
}

// The fit mask chooses which points get the profile fit, not which are found: the same points,
// those under the mask as fitted without it (the blur is estimated from all edges either way),
// the others at their facet zero crossing.
TEST(SubpixelEdges, FitMaskLeavesPointsOutsideItAtTheirFacetPosition) {
  SceneSpec spec;
  spec.size = {160, 120};
  spec.blurSigma = 1.0;
  spec.noiseSigma = 1.0;
  Scene scene(spec);
  scene.addDisc({50.3, 60.2}, 25, 160);
  scene.addDisc({115.6, 58.9}, 25, 160);
  const cv::Mat image = scene.render();
  const cv::Rect box(10, 10, 140, 100);

  EdgeParams fitted, facetOnly, half;
  fitted.roi = facetOnly.roi = half.roi = box;
  facetOnly.fitProfile = false;
  half.fitMask = cv::Mat::zeros(box.size(), CV_8U);  // of the ROI's size: the left disc's side
  half.fitMask(cv::Rect(0, 0, 70, 100)).setTo(255);
  const EdgeContours all = detectSubpixelEdges(image, fitted);
  const EdgeContours none = detectSubpixelEdges(image, facetOnly);
  const EdgeContours mixed = detectSubpixelEdges(image, half);
  EXPECT_EQ(mixed.blurSigma, all.blurSigma);
  ASSERT_GT(mixed.points.size(), 200u);
  // Points are matched by their pixel; a point's curvature correction reads 8 points along its
  // contour, so the discs' points (each disc on one side of x = 80) are compared whole.
  const auto at = [](const EdgeContours& e, cv::Point2d near) -> const EdgePoint* {
    for (const auto& p : e.points)
      if (cvRound(p.position.x) == cvRound(near.x) && cvRound(p.position.y) == cvRound(near.y))
        return &p;
    return nullptr;
  };
  int left = 0, right = 0;
  for (const EdgePoint& p : mixed.points) {
    const EdgePoint* reference = at(p.position.x < 80 ? all : none, p.position);
    ASSERT_NE(reference, nullptr) << p.position;
    EXPECT_EQ(p.position, reference->position);
    ++(p.position.x < 80 ? left : right);
  }
  EXPECT_GT(left, 100);
  EXPECT_GT(right, 100);

  EdgeParams badMask;
  badMask.fitMask = cv::Mat::zeros(10, 10, CV_8U);
  EXPECT_THROW(detectSubpixelEdges(image, badMask), std::invalid_argument);
  badMask.fitMask = cv::Mat::zeros(image.size(), CV_32F);
  EXPECT_THROW(detectSubpixelEdges(image, badMask), std::invalid_argument);
}

TEST(AutoThresholds, ScaleWithContrastAndFindTheEdge) {
  double previousHigh = 0;
  for (double contrast : {30.0, 90.0, 180.0}) {
    SceneSpec spec;
    spec.size = {128, 128};
    spec.background = 40;
    spec.blurSigma = 1.0;
    spec.noiseSigma = 2.0;
    Scene scene(spec);
    scene.addDisc({64.2, 63.7}, 30, 40 + contrast);
    const cv::Mat image = scene.render();
    const EdgeGradient g = computeEdgeGradient(image);
    const CannyThresholds t = autoCannyThresholds(g.magnitude);
    EXPECT_GT(t.high, previousHigh) << "contrast " << contrast;
    EXPECT_LT(t.low, t.high);
    // Above the noise (gradient noise sigma ~ 0.2 grey/px here), below the edge's slope.
    EXPECT_GT(t.low, 0.5);
    EXPECT_LT(t.high, contrast / (1.04 * std::sqrt(2 * std::numbers::pi)));
    previousHigh = t.high;

    const EdgeContours edges = detectSubpixelEdges(image);  // automatic thresholds
    EXPECT_NEAR(edges.highThreshold, t.high, 0.25 * t.high);
    int onCircle = 0;
    for (const auto& p : edges.points)
      onCircle += std::abs(cv::norm(p.position - cv::Point2d(64.2, 63.7)) - 30) < 0.3;
    // One point per row/column crossing: 8 r / sqrt(2) ~ 170 on a circle of radius 30.
    EXPECT_GT(onCircle, 145) << "contrast " << contrast;
    EXPECT_LT(edges.points.size(), 180u) << "contrast " << contrast;  // and no noise points
  }
}

TEST(AutoThresholds, MaskSelectsTheRegion) {
  cv::Mat magnitude(10, 10, CV_32F, cv::Scalar(1.0f));
  magnitude(cv::Rect(0, 0, 5, 10)).setTo(50.0f);
  magnitude.at<float>(2, 7) = 20.0f;
  cv::Mat mask = cv::Mat::zeros(10, 10, CV_8U);
  mask(cv::Rect(5, 0, 5, 10)).setTo(255);
  const CannyThresholds inside = autoCannyThresholds(magnitude, mask);
  const CannyThresholds everywhere = autoCannyThresholds(magnitude);
  EXPECT_LT(inside.high, 20.0);
  EXPECT_GT(everywhere.high, 20.0);
  EXPECT_THROW(autoCannyThresholds(cv::Mat(10, 10, CV_8U)), std::invalid_argument);
}

TEST(Canny, HysteresisKeepsWeakPartsConnectedToStrongOnes) {
  // Vertical edge at x = 20.3 whose contrast fades from 120 (rows 0-29) to 30 (rows 50-79) --
  // slowly, so that the fade itself is no edge -- and a separate weak edge (contrast 30) at
  // x = 60.3 over all rows.
  cv::Mat image(80, 80, CV_8U);
  for (int y = 0; y < 80; ++y) {
    const double contrast = y < 30 ? 120.0 : (y < 50 ? 120.0 - 4.5 * (y - 30) : 30.0);
    for (int x = 0; x < 80; ++x) {
      const double a = contrast * std::clamp(x - 20.3 + 0.5, 0.0, 1.0);
      const double b = 30.0 * std::clamp(x - 60.3 + 0.5, 0.0, 1.0);
      image.at<uchar>(y, x) = cv::saturate_cast<uchar>(40 + a + b);
    }
  }
  cv::GaussianBlur(image, image, {7, 7}, 1.0);
  // Slopes seen through the 5x5 Sobel (which adds its own smoothing): strong ~ 38, weak ~ 9.5
  // grey levels per pixel; the fade is 4.5 per row.
  const cv::Mat edges = cannyEdges(image, 8, 25);
  auto count = [&](const cv::Mat& e, int x0, int y0, int y1) {
    return cv::countNonZero(e(cv::Rect(x0, y0, 5, y1 - y0)));
  };
  EXPECT_GE(count(edges, 18, 3, 30), 26);   // strong part: one pixel per row
  EXPECT_GE(count(edges, 18, 50, 77), 26);  // weak part, connected to the strong one
  EXPECT_EQ(count(edges, 58, 3, 77), 0);    // weak and isolated: dropped
  // With a low threshold above the weak slope the weak part goes too.
  EXPECT_EQ(count(cannyEdges(image, 15, 25), 18, 50, 77), 0);
  // And with a high threshold below it the isolated edge is kept.
  EXPECT_GE(count(cannyEdges(image, 5, 9), 58, 3, 77), 70);
}

TEST(Canny, GradientEqualsTheFiveByFiveSobelOfTheImage) {
  // The definition: cv::Sobel's 5x5 derivatives of the whole image with its border replicated,
  // for areas inside the image, on its border and on a corner, 8-bit and 16-bit.
  for (int depth : {CV_8U, CV_16U}) {
    SceneSpec spec;
    spec.size = {61, 47};
    spec.background = 30;
    spec.blurSigma = 0.8;
    spec.noiseSigma = 4.0;
    spec.depth = depth;
    Scene scene(spec);
    scene.addDisc({28.4, 22.1}, 17.0, 220);
    const cv::Mat image = scene.render();
    const int type = depth == CV_8U ? CV_16S : CV_32F;
    cv::Mat dx, dy;
    cv::Sobel(image, dx, type, 1, 0, 5, 1, 0, cv::BORDER_REPLICATE);
    cv::Sobel(image, dy, type, 0, 1, 5, 1, 0, cv::BORDER_REPLICATE);
    // scale * |(gx, gy)| in float, as the maps hold it.
    const auto scale = static_cast<float>((depth == CV_8U ? 1.0 : 1.0 / 256.0) / 128.0);
    cv::Mat fx, fy, magnitude(image.size(), CV_32F);
    dx.convertTo(fx, CV_32F);
    dy.convertTo(fy, CV_32F);
    for (int y = 0; y < image.rows; ++y)
      for (int x = 0; x < image.cols; ++x) {
        const float a = fx.at<float>(y, x), b = fy.at<float>(y, x);
        magnitude.at<float>(y, x) = scale * std::sqrt(a * a + b * b);
      }
    for (const cv::Rect area : {cv::Rect(0, 0, 61, 47), cv::Rect(9, 7, 30, 18),
                                cv::Rect(-3, 20, 12, 40), cv::Rect(50, 0, 20, 1)}) {
      const EdgeGradient g = computeEdgeGradient(image, area);
      const cv::Rect inside = area & cv::Rect(0, 0, image.cols, image.rows);
      ASSERT_EQ(g.area, inside);
      EXPECT_EQ(cv::countNonZero(g.gx != dx(inside)), 0) << "depth " << depth << " " << area;
      EXPECT_EQ(cv::countNonZero(g.gy != dy(inside)), 0) << "depth " << depth << " " << area;
      EXPECT_EQ(cv::countNonZero(g.magnitude != magnitude(inside)), 0) << "depth " << depth;
    }
  }
}

// A ring of runs (as an annulus is measured) that reaches the image's border, where the
// gradient replicates the border pixels.
RowRuns ringRuns(cv::Size size, cv::Point2d centre, double rIn, double rOut) {
  RowRuns runs;
  for (int y = 1; y < size.height - 1; ++y) {
    int start = -1;
    for (int x = 1; x <= size.width - 1; ++x) {
      const double d = std::hypot(x - centre.x, y - centre.y);
      const bool in = x < size.width - 1 && d >= rIn && d <= rOut;
      if (in && start < 0) start = x;
      if (!in && start >= 0) {
        runs.push_back({y, start, x});
        start = -1;
      }
    }
  }
  return runs;
}

TEST(Canny, OnRunsEqualsTheMaskedFullGradient) {
  cv::RNG rng(11);
  for (int depth : {CV_8U, CV_16U}) {
    SceneSpec spec;
    spec.size = {70, 60};
    spec.background = 40;
    spec.blurSigma = 1.0;
    spec.noiseSigma = 3.0;
    spec.depth = depth;
    Scene scene(spec);
    scene.addDisc({30.3, 27.6}, 24.0, 200);
    const cv::Mat image = scene.render();
    const cv::Rect area(0, 0, image.cols, image.rows);
    const RowRuns runs = ringRuns(image.size(), {30.3, 27.6}, 19.0, 29.0);
    const EdgeGradient full = computeEdgeGradient(image, area);
    const EdgeGradient onRuns = computeEdgeGradientOnRuns(image, area, runs);
    cv::Mat mask = cv::Mat::zeros(image.size(), CV_8U);
    for (const RowRun& r : runs) mask.row(r.y).colRange(r.x0, r.x1).setTo(255);
    cv::Mat near;
    cv::dilate(mask, near, cv::Mat::ones(3, 3, CV_8U));
    int compared = 0;
    for (int y = 0; y < image.rows; ++y)
      for (int x = 0; x < image.cols; ++x) {
        if (!near.at<uchar>(y, x)) continue;
        ++compared;
        ASSERT_EQ(onRuns.magnitude.at<float>(y, x), full.magnitude.at<float>(y, x))
            << "depth " << depth << " at " << x << "," << y;
        if (depth == CV_8U)
          ASSERT_EQ(onRuns.gx.at<short>(y, x), full.gx.at<short>(y, x));
        else
          ASSERT_EQ(onRuns.gy.at<float>(y, x), full.gy.at<float>(y, x));
      }
    EXPECT_GT(compared, 1500);
    const cv::Mat expected = cannyFromGradient(full, 3.0, 8.0, mask);
    const cv::Mat got = cannyOnRuns(onRuns, 3.0, 8.0, runs);
    EXPECT_EQ(cv::countNonZero(expected != got), 0) << "depth " << depth;
    EXPECT_GT(cv::countNonZero(got), 100);
  }
}

TEST(RowRuns, DilationGrowsByOnePixelAndMerges) {
  const RowRuns runs{{5, 2, 4}, {5, 6, 9}, {7, 3, 4}};
  const RowRuns grown = dilateRowRuns(runs, cv::Rect(0, 0, 9, 20));
  cv::Mat a = cv::Mat::zeros(20, 12, CV_8U), b = a.clone();
  for (const RowRun& r : runs) a.row(r.y).colRange(r.x0, r.x1).setTo(255);
  cv::dilate(a, a, cv::Mat::ones(3, 3, CV_8U));
  a.colRange(9, 12).setTo(0);  // the clip
  for (const RowRun& r : grown) {
    ASSERT_LT(r.x0, r.x1);
    b.row(r.y).colRange(r.x0, r.x1) += 1;
  }
  EXPECT_EQ(cv::countNonZero(a != b * 255), 0);  // each pixel once
  EXPECT_TRUE(dilateRowRuns({}, cv::Rect(0, 0, 9, 9)).empty());
}

TEST(RowRuns, AnnulusHoldsExactlyThePixelsOfThePerPixelTest) {
  cv::RNG rng(5);
  for (int trial = 0; trial < 200; ++trial) {
    const cv::Point2d c(rng.uniform(-5.0, 45.0), rng.uniform(-5.0, 45.0));
    const double rIn = trial % 5 == 0 ? 0.0 : rng.uniform(0.0, 15.0);
    const double rOut = rIn + rng.uniform(0.5, 12.0);
    const cv::Rect clip(2, 3, 36, 33);
    cv::Mat expected = cv::Mat::zeros(40, 40, CV_8U), got = expected.clone();
    for (int y = clip.y; y < clip.br().y; ++y)
      for (int x = clip.x; x < clip.br().x; ++x) {
        const double d = std::hypot(x - c.x, y - c.y);
        expected.at<uchar>(y, x) = d >= rIn && d <= rOut ? 1 : 0;
      }
    for (const RowRun& r : annulusRowRuns(c, rIn, rOut, clip)) {
      ASSERT_LT(r.x0, r.x1);
      got.row(r.y).colRange(r.x0, r.x1) += 1;
    }
    // Pixels exactly on a circle may fall either way by rounding; none lies there in this draw.
    ASSERT_EQ(cv::countNonZero(expected != got), 0) << "trial " << trial;
  }
}

TEST(SubpixelEdges, DiscIsOneClosedContourAndTheCurvatureCorrectionHelps) {
  SceneSpec spec;
  spec.size = {100, 100};
  spec.background = 40;
  spec.blurSigma = 1.0;
  Scene scene(spec);
  const cv::Point2d c{50.37, 49.81};
  const double r = 15;
  scene.addDisc(c, r, 140);
  const cv::Mat image = scene.render();
  EdgeParams params;
  params.linkContours = true;
  const EdgeContours raw = detectSubpixelEdges(image, params);
  ASSERT_FALSE(raw.contours.empty());
  size_t longest = 0;
  for (const auto& contour : raw.contours) longest = std::max(longest, contour.size());
  EXPECT_GE(longest, raw.points.size() * 9 / 10);
  // Consecutive points of a contour are neighbours (at most one point left out between them).
  for (const auto& contour : raw.contours)
    for (size_t i = 1; i < contour.size(); ++i)
      EXPECT_LT(cv::norm(raw.points[contour[i]].position - raw.points[contour[i - 1]].position),
                3.0);

  auto meanRadialError = [&](const EdgeContours& e) {
    double sum = 0;
    for (const auto& p : e.points) sum += cv::norm(p.position - c) - r;
    return sum / static_cast<double>(e.points.size());
  };
  params.correctCurvatureBias = true;
  const EdgeContours corrected = detectSubpixelEdges(image, params);
  const double before = meanRadialError(raw), after = meanRadialError(corrected);
  EXPECT_LT(before, -0.02);  // the bias exists: points lie inside the disc
  EXPECT_LT(std::abs(after), 0.5 * std::abs(before));
  EXPECT_NEAR(corrected.blurSigma, 1.0, 0.1);
}

TEST(SubpixelEdges, EmptyAndConstantImagesGiveNoPoints) {
  EXPECT_TRUE(detectSubpixelEdges(cv::Mat()).points.empty());
  EXPECT_TRUE(detectSubpixelEdges(cv::Mat(50, 60, CV_8U, cv::Scalar(90))).points.empty());
  EXPECT_TRUE(detectSubpixelEdges(cv::Mat(50, 60, CV_16U, cv::Scalar(9000))).points.empty());
  EXPECT_TRUE(detectSubpixelEdges(cv::Mat(3, 3, CV_8U, cv::Scalar(0))).points.empty());
}

TEST(SubpixelEdges, WrongTypeIsAClearError) {
  for (int type : {CV_8UC3, CV_32FC1, CV_16SC1}) {
    try {
      detectSubpixelEdges(cv::Mat(20, 20, type, cv::Scalar::all(0)));
      ADD_FAILURE() << "no exception for " << cv::typeToString(type);
    } catch (const std::invalid_argument& e) {
      EXPECT_NE(std::string(e.what()).find("8-bit or 16-bit single-channel"), std::string::npos);
      EXPECT_NE(std::string(e.what()).find(cv::typeToString(type)), std::string::npos);
    }
  }
}

}  // namespace
}  // namespace facet
