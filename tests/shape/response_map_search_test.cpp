// The top-level search against its definition: every candidate's score is the sum over the
// model's points of the response map at the point's pixel, 127 cos(theta - theta_bin) rounded
// and kept within 8 bits, over 127 n; and every pixel whose best sum reaches the threshold and is
// a local maximum is a candidate. The search computes those sums with vector intrinsics (AVX2
// where the processor has it) and skips blocks of background; neither may change a value.
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <numbers>
#include <thread>
#include <vector>

#include <opencv2/imgproc.hpp>

#include "algorithms/shape/find_shape_model.hpp"
#include "algorithms/shape/image_gradients.hpp"
#include "algorithms/shape/response_map_search.hpp"
#include "algorithms/shape/shape_model.hpp"
#include "algorithms/shape/shape_similarity.hpp"
#include "tests/shape/bracket_scenes.hpp"

namespace facet {
namespace {

using shape_detail::Candidate;
using shape_detail::Direction;

constexpr int kBins = 32;
constexpr double kTwoPi = 2.0 * std::numbers::pi;

// The response of the map of `bin` at a pixel with direction d: the search's float arithmetic
// and rounding (half to even), kept within 8 bits.
int response(const Direction& d, int bin) {
  const auto c = static_cast<float>(std::cos(bin * kTwoPi / kBins));
  const auto s = static_cast<float>(std::sin(bin * kTwoPi / kBins));
  const float v = d[0] * c + d[1] * s;
  return std::min(cvRound(v), 127);
}

// A template (one angle and scale): each point's pixel offset and map bin.
struct Template {
  std::vector<cv::Point> offsets;
  std::vector<int> bins;
};

Template templateOf(const std::vector<ShapePoint>& points, double angle, double scale) {
  const shape_detail::PosedPoints posed = shape_detail::posePoints(points, angle, scale);
  Template t{posed.offsets, {}};
  for (const auto& d : posed.directions) {
    const double theta = std::atan2(d.y, d.x);
    t.bins.push_back(((static_cast<int>(std::lround(theta / kTwoPi * kBins)) % kBins) + kBins) %
                     kBins);
  }
  return t;
}

// The template's sum with its reference point at (x, y); pixels outside the field add nothing.
// With `spread` each point inside the field adds its best response within `spread` pixels in x
// and y, or 0 where that is lower.
int directSum(const cv::Mat& field, const Template& t, int x, int y, int spread = 0) {
  int sum = 0;
  for (std::size_t i = 0; i < t.offsets.size(); ++i) {
    const int u = x + t.offsets[i].x, v = y + t.offsets[i].y;
    if (u < 0 || v < 0 || u >= field.cols || v >= field.rows) continue;
    if (spread == 0) {
      sum += response(field.at<Direction>(v, u), t.bins[i]);
      continue;
    }
    int best = 0;
    for (int b = std::max(v - spread, 0); b <= std::min(v + spread, field.rows - 1); ++b)
      for (int a = std::max(u - spread, 0); a <= std::min(u + spread, field.cols - 1); ++a)
        best = std::max(best, response(field.at<Direction>(b, a), t.bins[i]));
    sum += best;
  }
  return sum;
}

// Rigid, and with each point's best response within 1 or 2 pixels (FindParams::maxDeformation).
class TopLevelSearchSpread : public ::testing::TestWithParam<int> {};

TEST_P(TopLevelSearchSpread, ScoresAreTheDirectSumsAndNoLocalMaximumIsMissed) {
  const int spread = GetParam();
  // A model's top level and a scene's top level (pyramid level 3 of a 640x480 scene).
  const ShapeModel model = createShapeModel(testing::bracketTemplate());
  const int top = model.numLevels() - 1;
  const std::vector<ShapePoint>& points = model.levels[top].points;
  ASSERT_GT(points.size(), 10u);
  ASSERT_LE(points.size(), 250u);  // the search subsamples beyond 250 points; the sums here do not
  cv::Mat grey = testing::bracketScene({640, 480}, {{300, 220, 0.4, 1.0},
                                                    {150, 330, -2.0, 1.0},
                                                    {470, 110, 1.6, 1.0},
                                                    {480, 360, 2.9, 1.0},
                                                    {560, 240, -0.7, 1.0}});
  for (int l = 0; l < top; ++l) cv::pyrDown(grey, grey);
  shape_detail::DirectionField directions(grey, model.minContrast);
  directions.ensureAll();
  const cv::Mat& field = directions.directions();

  std::vector<double> angles;
  for (int k = 0; k < 24; ++k) angles.push_back(k * kTwoPi / 24);
  const double threshold = 0.4;
  const double separate = threshold;
  const auto candidates = shape_detail::searchTopLevel(field, points, angles, {1.0}, Polarity::Use,
                                                       spread, threshold, separate, 1);
  ASSERT_FALSE(candidates.empty());

  // Per pixel, directly: the best sum and template (the first of equal sums), and the second, as
  // the search keeps it going through the templates in order: a sum above the second and more
  // than 2 angle steps (of 24, around the circle) from the best template so far becomes the
  // second; a new best pushes the old one into the second where the two lie that far apart.
  const double norm = 127.0 * static_cast<double>(points.size());
  const int n = static_cast<int>(angles.size());
  const auto apart = [n](int a, int b) {
    const int d = std::abs(a - b);
    return std::min(d, n - d) > 2;
  };
  std::vector<Template> templates;
  for (const double a : angles) templates.push_back(templateOf(points, a, 1.0));
  cv::Mat value[2] = {cv::Mat(field.size(), CV_32S, cv::Scalar(0)),
                      cv::Mat(field.size(), CV_32S, cv::Scalar(0))};
  cv::Mat index[2] = {cv::Mat(field.size(), CV_32S, cv::Scalar(-1)),
                      cv::Mat(field.size(), CV_32S, cv::Scalar(-1))};
  for (int y = 0; y < field.rows; ++y)
    for (int x = 0; x < field.cols; ++x)
      for (int t = 0; t < n; ++t) {
        const int u = directSum(field, templates[static_cast<std::size_t>(t)], x, y, spread);
        int &b = value[0].at<int>(y, x), &bt = index[0].at<int>(y, x);
        int &s = value[1].at<int>(y, x), &st = index[1].at<int>(y, x);
        if (u <= s) continue;
        const bool far = bt >= 0 && apart(t, bt);
        if (u > b) {
          if (far) s = b, st = bt;
          b = u, bt = t;
        } else if (far) {
          s = u, st = t;
        }
      }

  // The candidates by definition: from `threshold`, the pixels' bests that no best within 1 px
  // beats (strict towards the top-left), taken strongest first (equal ones in raster order) and
  // kept where no kept one lies within 2 px and no best there lies 0.1 above; and from `separate`,
  // an entry (best or second) that no entry within 2 px and 2 angle steps beats, within 0.1 of
  // every best within 2 px.
  const auto inField = [&](int x, int y) {
    return x >= 0 && y >= 0 && x < field.cols && y < field.rows;
  };
  const auto beatenWithin = [&](int x, int y, int reach) {
    const int v = value[0].at<int>(y, x);
    for (int dy = -reach; dy <= reach; ++dy)
      for (int dx = -reach; dx <= reach; ++dx) {
        if (!inField(x + dx, y + dy) || (dx == 0 && dy == 0)) continue;
        const int u = value[0].at<int>(y + dy, x + dx);
        if (u > v || (u == v && (dy < 0 || (dy == 0 && dx < 0)))) return true;
      }
    return false;
  };
  std::vector<std::array<int, 3>> peaks;  // value, y, x of the 3x3 maxima
  for (int y = 0; y < field.rows; ++y)
    for (int x = 0; x < field.cols; ++x) {
      const int v = value[0].at<int>(y, x);
      if (v > 0 && v >= static_cast<int>(threshold * norm) && !beatenWithin(x, y, 1))
        peaks.push_back({v, y, x});
    }
  std::sort(peaks.begin(), peaks.end(), [](const auto& a, const auto& b) {
    return a[0] != b[0] ? a[0] > b[0] : (a[1] != b[1] ? a[1] < b[1] : a[2] < b[2]);
  });
  cv::Mat kept(field.size(), CV_8U, cv::Scalar(0));
  int strictMaxima = 0;  // maxima within 2 px: the greedy rule keeps them and more
  for (const auto& p : peaks) {
    const int y = p[1], x = p[2];
    bool free = true;
    for (int dy = -2; dy <= 2; ++dy)
      for (int dx = -2; dx <= 2; ++dx)
        if (inField(x + dx, y + dy) && kept.at<uchar>(y + dy, x + dx)) free = false;
    for (int dy = -2; dy <= 2; ++dy)
      for (int dx = -2; dx <= 2; ++dx)
        if (inField(x + dx, y + dy) &&
            p[0] < value[0].at<int>(y + dy, x + dx) - static_cast<int>(std::lround(0.1 * norm)))
          free = false;
    if (free) kept.at<uchar>(y, x) = 1;
    if (!beatenWithin(x, y, 2)) {
      ++strictMaxima;
      EXPECT_TRUE(free) << "a maximum within 2 px at " << x << "," << y << " was suppressed";
    }
  }
  EXPECT_GT(cv::countNonZero(kept), strictMaxima);  // the scenes have ridges: the rule is exercised
  std::vector<std::array<int, 3>> expected;         // x, y, template
  // Candidates that are no maximum over position.
  int seconds = 0;
  for (int y = 0; y < field.rows; ++y)
    for (int x = 0; x < field.cols; ++x)
      for (int layer = 0; layer < 2; ++layer) {
        const int v = value[layer].at<int>(y, x), t = index[layer].at<int>(y, x);
        if (v <= 0 || v < static_cast<int>(threshold * norm)) continue;
        const bool positionMax = layer == 0 && kept.at<uchar>(y, x);
        bool poseMax = true, nearBest = true;
        for (int dy = -2; dy <= 2; ++dy)
          for (int dx = -2; dx <= 2; ++dx) {
            const int xx = x + dx, yy = y + dy;
            if (!inField(xx, yy)) continue;
            const int u = value[0].at<int>(yy, xx);
            if (v < u - static_cast<int>(std::lround(0.1 * norm))) nearBest = false;
            for (int other = 0; other < 2; ++other) {
              if (dx == 0 && dy == 0 && other == layer) continue;
              const int w = value[other].at<int>(yy, xx), wt = index[other].at<int>(yy, xx);
              if (w < v || wt < 0 || apart(t, wt)) continue;
              if (w > v || dy < 0 || (dy == 0 && (dx < 0 || (dx == 0 && other < layer))))
                poseMax = false;
            }
          }
        const bool separatePeak = v >= static_cast<int>(separate * norm) && nearBest && poseMax;
        if (positionMax || separatePeak) expected.push_back({x, y, t});
        if (!positionMax && separatePeak) ++seconds;
      }
  for (const auto& e : expected) {
    const auto c = std::find_if(candidates.begin(), candidates.end(), [&](const Candidate& c) {
      return static_cast<int>(c.x) == e[0] && static_cast<int>(c.y) == e[1] &&
             std::abs(c.angle - angles[static_cast<std::size_t>(e[2])]) < 1e-12;
    });
    ASSERT_NE(c, candidates.end()) << "at " << e[0] << "," << e[1] << " template " << e[2];
    const int sum = directSum(field, templates[static_cast<std::size_t>(e[2])], e[0], e[1], spread);
    EXPECT_DOUBLE_EQ(c->score, sum / norm) << "at " << e[0] << "," << e[1];
  }
  EXPECT_EQ(expected.size(), candidates.size());
  // The scenes hold such peaks: the rule is exercised.
  EXPECT_GT(seconds, 0);
}

INSTANTIATE_TEST_SUITE_P(Rigid, TopLevelSearchSpread, ::testing::Values(0));
INSTANTIATE_TEST_SUITE_P(Deformable, TopLevelSearchSpread, ::testing::Values(1, 2));

TEST(TopLevelSearch, AnAlignedDirectionLongerThan127DoesNotWrap) {
  // A rounded direction can be longer than 127: (117, 51) is 127.6 long, and its response on
  // bin 2 (22.5 degrees) rounds to 128, which does not fit in 8 bits. Kept as 127, a field of
  // such pixels matches a model of 22.5-degree points perfectly; wrapped to -128 it would match
  // worst of all.
  cv::Mat field(40, 40, CV_8SC2, cv::Scalar(117, 51));
  std::vector<ShapePoint> points;
  const cv::Point2f along(static_cast<float>(std::cos(kTwoPi / 16)),
                          static_cast<float>(std::sin(kTwoPi / 16)));
  for (int k = -5; k <= 5; ++k) points.push_back({{static_cast<float>(k), 0.0f}, along});
  const auto candidates =
      shape_detail::searchTopLevel(field, points, {0.0}, {1.0}, Polarity::Use, 0, 0.9, 0.9, 1);
  ASSERT_FALSE(candidates.empty());
  EXPECT_NEAR(candidates.front().score, 1.0, 1e-12);
}

// The thread keeps its response maps from search to search and clears only what a search wrote:
// whatever came before, a search's candidates are those of a thread that never searched.
TEST(TopLevelSearch, ASearchSeesNothingOfTheThreadsEarlierSearches) {
  const ShapeModel model = createShapeModel(testing::bracketTemplate());
  const int top = model.numLevels() - 1;
  const std::vector<ShapePoint>& points = model.levels[top].points;
  const auto topField = [&](const cv::Mat& scene) {
    cv::Mat grey = scene;
    for (int l = 0; l < top; ++l) cv::pyrDown(grey, grey);
    shape_detail::DirectionField directions(grey, model.minContrast);
    directions.ensureAll();
    return directions.directions().clone();
  };
  const cv::Mat busy = topField(testing::bracketScene(
      {640, 480}, {{300, 220, 0.4, 1.0}, {150, 330, -2.0, 1.0}, {480, 120, 2.5, 1.0}}));
  const cv::Mat blank(busy.size(), busy.type(), cv::Scalar::all(0));
  // Smaller, with the parts elsewhere: the earlier maps' layout does not fit it.
  const cv::Mat other = topField(testing::bracketScene({480, 400}, {{200, 180, 1.0, 1.0}}));
  std::vector<double> angles;
  for (int k = 0; k < 24; ++k) angles.push_back(k * kTwoPi / 24);
  for (const int spread : {0, 2}) {
    const auto search = [&](const cv::Mat& field) {
      return shape_detail::searchTopLevel(field, points, angles, {1.0}, Polarity::Use, spread, 0.3,
                                          0.3, 1);
    };
    std::vector<Candidate> fresh;
    std::thread([&] { fresh = search(other); }).join();
    ASSERT_FALSE(fresh.empty());

    ASSERT_FALSE(search(busy).empty());
    EXPECT_TRUE(search(blank).empty()) << "spread " << spread;
    (void)search(busy);
    const std::vector<Candidate> after = search(other);
    ASSERT_EQ(after.size(), fresh.size()) << "spread " << spread;
    for (std::size_t i = 0; i < after.size(); ++i) {
      EXPECT_EQ(after[i].x, fresh[i].x);
      EXPECT_EQ(after[i].y, fresh[i].y);
      EXPECT_EQ(after[i].angle, fresh[i].angle);
      EXPECT_EQ(after[i].score, fresh[i].score);
    }
  }
}

}  // namespace
}  // namespace facet
