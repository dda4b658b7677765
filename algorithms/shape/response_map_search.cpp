#include "algorithms/shape/response_map_search.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <functional>
#include <numbers>

#include <opencv2/core/hal/intrin.hpp>

#include "algorithms/shape/image_gradients.hpp"
#include "algorithms/shape/response_sums.hpp"
#include "algorithms/shape/shape_similarity.hpp"

namespace facet::shape_detail {
namespace {

constexpr double kTwoPi = 2.0 * std::numbers::pi;
constexpr int kBins = 32;  // quantised orientations
// 16-bit sums: 250 * 127 < 32767.
constexpr int kMaxTopPoints = 250;

struct TopTemplate {
  double angle = 0.0;
  double scale = 1.0;
  std::vector<std::ptrdiff_t> sources;  // map plane of the point's bin + its offset in the plane
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
  // Rows are summed in whole blocks of kSumAlign; the pixels past w read zeros and are ignored.
  const int paddedW = (w + kSumAlign - 1) / kSumAlign * kSumAlign;
  const int stride = paddedW + 2 * border;
  const auto plane = static_cast<std::ptrdiff_t>(stride) * (h + 2 * border);
  const bool local = polarity == Polarity::IgnoreLocal;

  // 8-bit maps (half the memory the sums read), widened as they are added.
  std::vector<std::int8_t> maps(static_cast<std::size_t>(plane) * kBins, 0);
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
      const std::ptrdiff_t base = static_cast<std::ptrdiff_t>(y + border) * stride + border;
      for (int x = 0; x < w; ++x) {
        if (row[x][0] == 0 && row[x][1] == 0) continue;
        for (int b = 0; b < kBins; ++b) {
          float v = row[x][0] * cosB[b] + row[x][1] * sinB[b];
          if (local) v = std::abs(v);
          // A rounded direction may be up to 127.7 long: clamped, so that 128 cannot wrap.
          maps[static_cast<std::size_t>(b * plane + base + x)] =
              static_cast<std::int8_t>(std::min(cvRound(v), 127));
        }
      }
    }
  });

  std::vector<TopTemplate> templates;
  for (double s : scales) {
    for (double a : angles) {
      TopTemplate t{a, s, {}};
      const PosedPoints posed = posePoints(points, a, s);
      for (std::size_t i = 0; i < points.size(); ++i) {
        const double theta = std::atan2(posed.directions[i].y, posed.directions[i].x);
        const int bin =
            ((static_cast<int>(std::lround(theta / kTwoPi * kBins)) % kBins) + kBins) % kBins;
        t.sources.push_back(bin * plane + posed.offsets[i].y * stride + posed.offsets[i].x);
      }
      templates.push_back(std::move(t));
    }
  }

  // Best template per pixel (the first one of equal sums).
  std::vector<std::int16_t> best(static_cast<std::size_t>(paddedW) * h, 0);
  std::vector<std::int32_t> bestTemplate(best.size(), -1);
  const bool global = polarity == Polarity::IgnoreGlobal;
  auto work = [&](int y0, int y1) {
    alignas(16) std::int16_t sums[kSumBlock];
    for (int y = y0; y < y1; ++y) {
      const std::int8_t* row =
          maps.data() + static_cast<std::ptrdiff_t>(y + border) * stride + border;
      std::int16_t* bestRow = best.data() + static_cast<std::size_t>(y) * paddedW;
      std::int32_t* bestIdx = bestTemplate.data() + static_cast<std::size_t>(y) * paddedW;
      for (std::size_t t = 0; t < templates.size(); ++t) {
        const std::vector<std::ptrdiff_t>& sources = templates[t].sources;
        for (int x0 = 0; x0 < paddedW; x0 += kSumBlock) {
          const int n = std::min(kSumBlock, paddedW - x0);
          sumResponses(row + x0, sources.data(), sources.size(), n, sums);
          for (int k = 0; k < n; k += 8) {
            cv::v_int16x8 v = cv::v_load_aligned(sums + k);
            if (global) v = cv::v_reinterpret_as_s16(cv::v_abs(v));
            std::int16_t* b = bestRow + x0 + k;
            // Improvements become rare after the first templates: test 8 pixels at once.
            if (!cv::v_check_any(v > cv::v_load(b))) continue;
            cv::v_store_aligned(sums + k, v);
            for (int j = k; j < k + 8; ++j)
              if (sums[j] > b[j - k])
                b[j - k] = sums[j], bestIdx[x0 + j] = static_cast<std::int32_t>(t);
          }
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
      const std::int16_t v = best[static_cast<std::size_t>(y) * paddedW + x];
      if (v < minSum || v <= 0) continue;
      bool isMax = true;
      for (int dy = -r; dy <= r && isMax; ++dy)
        for (int dx = -r; dx <= r; ++dx) {
          const int xx = x + dx, yy = y + dy;
          if ((dx == 0 && dy == 0) || xx < 0 || yy < 0 || xx >= w || yy >= h) continue;
          const std::int16_t u = best[static_cast<std::size_t>(yy) * paddedW + xx];
          // Strict on one side so that a plateau yields one maximum.
          if (u > v || (u == v && (dy < 0 || (dy == 0 && dx < 0)))) {
            isMax = false;
            break;
          }
        }
      if (!isMax) continue;
      const TopTemplate& tpl = templates[bestTemplate[static_cast<std::size_t>(y) * paddedW + x]];
      candidates.push_back({double(x), double(y), tpl.angle, tpl.scale, v / norm});
    }
  }
  std::sort(candidates.begin(), candidates.end(),
            [](const Candidate& a, const Candidate& b) { return a.score > b.score; });
  if (static_cast<int>(candidates.size()) > maxCandidates) candidates.resize(maxCandidates);
  return candidates;
}

}  // namespace facet::shape_detail
