#include "algorithms/shape/response_map_search.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <functional>
#include <numbers>

#include "algorithms/shape/image_gradients.hpp"
#include "algorithms/shape/shape_similarity.hpp"

namespace facet::shape_detail {
namespace {

constexpr double kTwoPi = 2.0 * std::numbers::pi;
constexpr int kBins = 32;           // quantised orientations
constexpr int kMaxTopPoints = 250;  // 16-bit sums: 250 * 127 < 32767

struct TopTemplate {
  double angle = 0.0;
  double scale = 1.0;
  std::vector<int> offsets;  // into a padded map plane
  std::vector<int> bins;
};

}  // namespace

std::vector<Candidate> searchTopLevel(const cv::Mat& field,
                                      const std::vector<ShapePoint>& modelPoints,
                                      const std::vector<double>& angles,
                                      const std::vector<double>& scales, Polarity polarity,
                                      double threshold, int threads, int maxCandidates) {
  std::vector<ShapePoint> points = modelPoints;
  if (points.size() > kMaxTopPoints) {
    std::vector<ShapePoint> kept;
    const double stride = static_cast<double>(points.size()) / kMaxTopPoints;
    for (int i = 0; i < kMaxTopPoints; ++i)
      kept.push_back(points[static_cast<std::size_t>(i * stride)]);
    points.swap(kept);
  }
  double radius = 0.0;
  for (const auto& p : points)
    radius = std::max(radius, std::hypot(double(p.position.x), double(p.position.y)));
  const int border = static_cast<int>(std::ceil(radius * scales.back())) + 2;
  const int w = field.cols, h = field.rows;
  const int stride = w + 2 * border;
  const std::size_t plane = static_cast<std::size_t>(stride) * (h + 2 * border);
  const bool local = polarity == Polarity::IgnoreLocal;

  std::vector<std::int8_t> maps(plane * kBins, 0);
  std::array<float, kBins> cosB{}, sinB{};
  for (int b = 0; b < kBins; ++b) {
    cosB[b] = static_cast<float>(std::cos(b * kTwoPi / kBins));
    sinB[b] = static_cast<float>(std::sin(b * kTwoPi / kBins));
  }
  threads = std::clamp(threads, 1, 8);
  // Rows in parallel stripes on OpenCV's worker pool (the algorithms start no threads of their
  // own); every stripe writes its own rows, so the result does not depend on the stripes.
  auto inStripes = [&](const std::function<void(int, int)>& rows) {
    if (threads == 1 || h < 2 * threads) {
      rows(0, h);
      return;
    }
    cv::parallel_for_(
        cv::Range(0, threads),
        [&](const cv::Range& r) {
          for (int k = r.start; k < r.end; ++k) rows(h * k / threads, h * (k + 1) / threads);
        },
        threads);
  };
  inStripes([&](int y0, int y1) {
    for (int y = y0; y < y1; ++y) {
      const auto* row = field.ptr<Direction>(y);
      const std::size_t base = static_cast<std::size_t>(y + border) * stride + border;
      for (int x = 0; x < w; ++x) {
        if (row[x][0] == 0 && row[x][1] == 0) continue;
        for (int b = 0; b < kBins; ++b) {
          float v = row[x][0] * cosB[b] + row[x][1] * sinB[b];
          if (local) v = std::abs(v);
          maps[b * plane + base + x] = static_cast<std::int8_t>(std::lround(v));
        }
      }
    }
  });

  std::vector<TopTemplate> templates;
  for (double s : scales) {
    for (double a : angles) {
      TopTemplate t{a, s, {}, {}};
      const PosedPoints posed = posePoints(points, a, s);
      for (std::size_t i = 0; i < points.size(); ++i) {
        t.offsets.push_back(posed.offsets[i].y * stride + posed.offsets[i].x);
        const double theta = std::atan2(posed.directions[i].y, posed.directions[i].x);
        t.bins.push_back(((static_cast<int>(std::lround(theta / kTwoPi * kBins)) % kBins) + kBins) %
                         kBins);
      }
      templates.push_back(std::move(t));
    }
  }

  // Best template per pixel.
  std::vector<std::int16_t> best(static_cast<std::size_t>(w) * h, 0);
  std::vector<std::int32_t> bestTemplate(best.size(), -1);
  const bool global = polarity == Polarity::IgnoreGlobal;
  auto work = [&](int y0, int y1) {
    std::vector<std::int16_t> acc(w);
    for (int y = y0; y < y1; ++y) {
      const std::size_t rowBase = static_cast<std::size_t>(y + border) * stride + border;
      std::int16_t* bestRow = best.data() + static_cast<std::size_t>(y) * w;
      std::int32_t* bestIdx = bestTemplate.data() + static_cast<std::size_t>(y) * w;
      for (std::size_t t = 0; t < templates.size(); ++t) {
        const TopTemplate& tpl = templates[t];
        std::fill(acc.begin(), acc.end(), 0);
        std::int16_t* a = acc.data();
        for (std::size_t i = 0; i < tpl.offsets.size(); ++i) {
          const std::int8_t* src = maps.data() + tpl.bins[i] * plane + rowBase + tpl.offsets[i];
          for (int x = 0; x < w; ++x) a[x] = static_cast<std::int16_t>(a[x] + src[x]);
        }
        for (int x = 0; x < w; ++x) {
          const std::int16_t v = global ? static_cast<std::int16_t>(std::abs(a[x])) : a[x];
          if (v > bestRow[x]) bestRow[x] = v, bestIdx[x] = static_cast<std::int32_t>(t);
        }
      }
    }
  };
  inStripes(work);

  // Local maxima above the threshold.
  const double norm = 127.0 * static_cast<double>(points.size());
  const auto minSum = static_cast<std::int16_t>(std::min(32767.0, threshold * norm));
  std::vector<Candidate> candidates;
  constexpr int r = 2;
  for (int y = 0; y < h; ++y) {
    for (int x = 0; x < w; ++x) {
      const std::int16_t v = best[static_cast<std::size_t>(y) * w + x];
      if (v < minSum || v <= 0) continue;
      bool isMax = true;
      for (int dy = -r; dy <= r && isMax; ++dy)
        for (int dx = -r; dx <= r; ++dx) {
          const int xx = x + dx, yy = y + dy;
          if ((dx == 0 && dy == 0) || xx < 0 || yy < 0 || xx >= w || yy >= h) continue;
          const std::int16_t u = best[static_cast<std::size_t>(yy) * w + xx];
          // Strict on one side so that a plateau yields one maximum.
          if (u > v || (u == v && (dy < 0 || (dy == 0 && dx < 0)))) {
            isMax = false;
            break;
          }
        }
      if (!isMax) continue;
      const TopTemplate& tpl = templates[bestTemplate[static_cast<std::size_t>(y) * w + x]];
      candidates.push_back({double(x), double(y), tpl.angle, tpl.scale, v / norm});
    }
  }
  std::sort(candidates.begin(), candidates.end(),
            [](const Candidate& a, const Candidate& b) { return a.score > b.score; });
  if (static_cast<int>(candidates.size()) > maxCandidates) candidates.resize(maxCandidates);
  return candidates;
}

}  // namespace facet::shape_detail
