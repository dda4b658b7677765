#include "algorithms/shape/response_map_search.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <functional>
#include <numbers>

#include <opencv2/core/hal/intrin.hpp>
#include <opencv2/imgproc.hpp>

#include "algorithms/shape/image_gradients.hpp"
#include "algorithms/shape/response_sums.hpp"
#include "algorithms/shape/shape_similarity.hpp"
#include "algorithms/shape/zeroed_mat.hpp"

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

// One template's points as the sums read them: quantised direction bin and offset (pixels).
struct TemplateShape {
  std::vector<int> bins;
  std::vector<cv::Point> offsets;
};

// The templates of one model level at all angles and scales. A line searches one model in image
// after image, and posing its points with an atan2 each costs a twentieth of a 640x480 search:
// the thread keeps the sets of its last searches, found again by their exact inputs.
struct TemplateSet {
  std::vector<ShapePoint> points;
  std::vector<double> angles, scales;
  std::vector<TemplateShape> shapes;  // scale-major, as the search loops
  int sharing = 1;                    // the most points of one template on the same pixel
};

template <typename T>
bool sameBits(const std::vector<T>& a, const std::vector<T>& b) {
  return a.size() == b.size() && std::memcmp(a.data(), b.data(), a.size() * sizeof(T)) == 0;
}

const TemplateSet& templateSet(const std::vector<ShapePoint>& points,
                               const std::vector<double>& angles,
                               const std::vector<double>& scales) {
  static_assert(sizeof(ShapePoint) == 4 * sizeof(float));
  thread_local std::vector<TemplateSet> kept;
  for (const TemplateSet& set : kept)
    if (sameBits(set.points, points) && sameBits(set.angles, angles) &&
        sameBits(set.scales, scales))
      return set;
  TemplateSet set{points, angles, scales, {}, 1};
  for (double s : scales) {
    for (double a : angles) {
      TemplateShape shape;
      const PosedPoints posed = posePoints(points, a, s);
      std::vector<cv::Point> pixels = posed.offsets;
      std::sort(pixels.begin(), pixels.end(), [](const cv::Point& p, const cv::Point& q) {
        return p.y != q.y ? p.y < q.y : p.x < q.x;
      });
      for (std::size_t i = 0, j = 0; i < pixels.size(); i = j) {
        while (j < pixels.size() && pixels[j] == pixels[i]) ++j;
        set.sharing = std::max(set.sharing, static_cast<int>(j - i));
      }
      for (std::size_t i = 0; i < points.size(); ++i) {
        const double theta = std::atan2(posed.directions[i].y, posed.directions[i].x);
        shape.bins.push_back(
            ((static_cast<int>(std::lround(theta / kTwoPi * kBins)) % kBins) + kBins) % kBins);
      }
      shape.offsets = posed.offsets;
      set.shapes.push_back(std::move(shape));
    }
  }
  constexpr std::size_t kKeptSets = 4;
  if (kept.size() >= kKeptSets) kept.erase(kept.begin());
  kept.push_back(std::move(set));
  return kept.back();
}

// The top level's response maps: one plane per orientation bin, in each the image's pixels
// inside a border, zero where the image has no direction. The thread keeps its buffer all zero
// between searches: a search clears the columns it wrote on each row, not the whole buffer,
// whose pages then stay mapped, and those it never wrote are never touched (a fresh page costs a
// fault on its first touch, zeroed_mat.hpp). Buffers above kKeptBytes are the search's own.
class MapPlanes {
 public:
  MapPlanes(std::ptrdiff_t plane, int stride, int border, cv::Size image)
      : plane_(plane), stride_(stride), border_(border), written_(image.height, cv::Range(0, 0)) {
    constexpr std::size_t kKeptBytes = std::size_t{64} << 20;
    thread_local cv::Mat kept;
    const auto bytes = static_cast<std::size_t>(plane) * kBins;
    if (bytes > kKeptBytes) {
      own_ = zeroedMat({static_cast<int>(plane), kBins}, CV_8S);
      data_ = own_.ptr<std::int8_t>();
      return;
    }
    if (kept.total() < bytes) kept = zeroedMat({static_cast<int>(plane), kBins}, CV_8S);
    data_ = kept.ptr<std::int8_t>();
  }
  ~MapPlanes() {
    if (!own_.empty()) return;
    for (std::size_t y = 0; y < written_.size(); ++y) {
      const cv::Range cols = written_[y];
      if (cols.empty()) continue;
      for (int b = 0; b < kBins; ++b)
        std::memset(row(b, static_cast<int>(y)) + cols.start, 0, static_cast<size_t>(cols.size()));
    }
  }
  MapPlanes(const MapPlanes&) = delete;
  MapPlanes& operator=(const MapPlanes&) = delete;

  [[nodiscard]] std::int8_t* data() const { return data_; }
  // Image row y of bin b's plane.
  [[nodiscard]] std::int8_t* row(int b, int y) const {
    return data_ + b * plane_ + static_cast<std::ptrdiff_t>(y + border_) * stride_ + border_;
  }
  // Columns [cols.start, cols.end) of image row y hold values now (in every plane).
  void wrote(int y, cv::Range cols) { written_[static_cast<std::size_t>(y)] = cols; }

 private:
  std::ptrdiff_t plane_;
  int stride_, border_;
  std::vector<cv::Range> written_;
  cv::Mat own_;
  std::int8_t* data_ = nullptr;
};

// Two peaks in angle at a pixel are separate beyond the reach of the wider look below the top
// (find_shape_model.cpp), and only one within kClusterMargin (find_shape_model.cpp) of the best
// nearby could still be the part's.
constexpr int kApartSteps = 2;
constexpr double kPeakMargin = 0.1;

// Angle steps between two templates (scale-major, angles inner), around the circle when the
// angles cover it.
class AngleSteps {
 public:
  explicit AngleSteps(const std::vector<double>& angles) : n_(static_cast<int>(angles.size())) {
    if (n_ >= 3) {
      const double step = std::abs(angles[1] - angles[0]);
      circle_ = std::abs(step * n_ - kTwoPi) < 0.5 * step;
    }
  }
  // Whether templates a and b lie more than kApartSteps angle steps apart.
  [[nodiscard]] bool apart(std::int32_t a, std::int32_t b) const {
    int d = std::abs(a % n_ - b % n_);
    if (circle_) d = std::min(d, n_ - d);
    return d > kApartSteps;
  }

 private:
  int n_;
  bool circle_ = false;
};

}  // namespace

std::vector<Candidate> searchTopLevel(const cv::Mat& field,
                                      const std::vector<ShapePoint>& modelPoints,
                                      const std::vector<double>& angles,
                                      const std::vector<double>& scales, Polarity polarity,
                                      int spread, double threshold, double separateThreshold,
                                      int threads) {
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
  MapPlanes planes(plane, stride, border, {w, h});
  std::int8_t* const maps = planes.data();
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
      int first = w, end = 0;  // the columns written
      for (int x = 0; x < w; ++x) {
        if (row[x][0] == 0 && row[x][1] == 0) continue;
        first = std::min(first, x), end = x + 1;
        for (int b = 0; b < kBins; ++b) {
          float v = row[x][0] * cosB[b] + row[x][1] * sinB[b];
          if (local) v = std::abs(v);
          // Spread, a point scores its best response nearby or 0 (as scorePose): never below.
          if (spread > 0) v = std::max(v, 0.0f);
          // A rounded direction may be up to 127.7 long: clamped, so that 128 cannot wrap.
          maps[static_cast<std::size_t>(b * plane + base + x)] =
              static_cast<std::int8_t>(std::min(cvRound(v), 127));
        }
      }
      if (end > first) planes.wrote(y, {first, end});
    }
  });
  // The square a point's best response is taken from (spread > 0).
  const cv::Mat spreadSquare =
      spread > 0 ? cv::getStructuringElement(cv::MORPH_RECT, {2 * spread + 1, 2 * spread + 1})
                 : cv::Mat();
  if (spread > 0) {
    // The best response within `spread` of each pixel, per orientation: a maximum filter over the
    // image (a point outside it scores 0, as at spread 0). OpenCV dilates unsigned bytes;
    // flipping the sign bit maps -128..127 onto 0..255 in order. It writes every pixel.
    for (int y = 0; y < h; ++y) planes.wrote(y, {0, w});
    for (int b = 0; b < kBins; ++b) {
      cv::Mat map(h + 2 * border, stride, CV_8U, maps + static_cast<std::size_t>(b * plane));
      cv::Mat inImage = map(cv::Rect(border, border, w, h));
      cv::bitwise_xor(inImage, cv::Scalar(0x80), inImage);
      cv::dilate(inImage, inImage, spreadSquare, {-1, -1}, 1,
                 cv::BORDER_CONSTANT | cv::BORDER_ISOLATED);
      cv::bitwise_xor(inImage, cv::Scalar(0x80), inImage);
    }
  }

  // Offsets lie within the border, less than half a row's stride either side: a pixel's offset
  // y * stride + x is unique, so the set's sharing (counted per (x, y)) is the same.
  const TemplateSet& set = templateSet(points, angles, scales);
  const int sharing = set.sharing;
  std::vector<TopTemplate> templates;
  std::size_t shapeIndex = 0;
  for (double s : scales) {
    for (double a : angles) {
      TopTemplate t{a, s, {}};
      const TemplateShape& shape = set.shapes[shapeIndex++];
      t.sources.reserve(shape.bins.size());
      for (std::size_t i = 0; i < shape.bins.size(); ++i)
        t.sources.push_back(shape.bins[i] * plane + shape.offsets[i].y * stride +
                            shape.offsets[i].x);
      templates.push_back(std::move(t));
    }
  }

  const double norm = 127.0 * static_cast<double>(points.size());
  const auto minSum = static_cast<std::int16_t>(std::min(32767.0, threshold * norm));

  // A point adds at most 127, and only on a pixel that has a direction: a pixel whose
  // neighbourhood (the model's reach) holds fewer than minSum / (127 sharing) such pixels scores
  // below the threshold at every angle and scale. Such pixels are neither candidates nor
  // neighbours that could suppress one, so blocks of them are skipped without changing the
  // result: on plain background, most of the image.
  const int blockW = std::min(kSumBlock, paddedW);
  const int blocksPerRow = (paddedW + blockW - 1) / blockW;
  std::vector<std::uint8_t> live(static_cast<std::size_t>(h) * blocksPerRow, 0);
  {
    cv::Mat directed(h, w, CV_8U), count;
    for (int y = 0; y < h; ++y) {
      const auto* row = field.ptr<Direction>(y);
      auto* d = directed.ptr<uchar>(y);
      for (int x = 0; x < w; ++x) d[x] = (row[x][0] != 0 || row[x][1] != 0) ? 1 : 0;
    }
    // Spread, a map is non-zero within `spread` of a pixel with a direction.
    if (spread > 0) cv::dilate(directed, directed, spreadSquare);
    cv::integral(directed, count, CV_32S);
    const int reach = border;
    for (int y = 0; y < h; ++y) {
      const int ya = std::max(0, y - reach), yb = std::min(h, y + reach + 1);
      const int* top = count.ptr<int>(ya);
      const int* bottom = count.ptr<int>(yb);
      for (int x = 0; x < w; ++x) {
        const int xa = std::max(0, x - reach), xb = std::min(w, x + reach + 1);
        const int directedNear = bottom[xb] - bottom[xa] - top[xb] + top[xa];
        if (127LL * sharing * directedNear >= minSum)
          live[static_cast<std::size_t>(y) * blocksPerRow + x / blockW] = 1;
      }
    }
  }

  // Per pixel, the best template (the first one of equal sums) and the best of those more than
  // kApartSteps angle steps from it: a second peak in angle. Where the top level's score has two
  // peaks in angle at the part's pixel (a chessboard's quarter turns, the near-symmetric turns
  // of a texture), the best angle alone could be the wrong one, tracked down to a wrong pose,
  // while the part's own angle was suppressed (a part scoring 0.99 missed, 0.87 returned).
  const AngleSteps steps(angles);
  std::vector<std::int16_t> best(static_cast<std::size_t>(paddedW) * h, 0);
  std::vector<std::int16_t> second(best.size(), 0);
  std::vector<std::int32_t> bestTemplate(best.size(), -1);
  std::vector<std::int32_t> secondTemplate(best.size(), -1);
  const bool global = polarity == Polarity::IgnoreGlobal;
  auto work = [&](int y0, int y1) {
    alignas(16) std::int16_t sums[kSumBlock];
    for (int y = y0; y < y1; ++y) {
      const std::int8_t* row = maps + static_cast<std::ptrdiff_t>(y + border) * stride + border;
      const std::size_t rowStart = static_cast<std::size_t>(y) * paddedW;
      std::int16_t* bestRow = best.data() + rowStart;
      std::int16_t* secondRow = second.data() + rowStart;
      std::int32_t* bestIdx = bestTemplate.data() + rowStart;
      std::int32_t* secondIdx = secondTemplate.data() + rowStart;
      for (int x0 = 0; x0 < paddedW; x0 += blockW) {
        if (!live[static_cast<std::size_t>(y) * blocksPerRow + x0 / blockW]) continue;
        const int n = std::min(blockW, paddedW - x0);
        for (std::size_t t = 0; t < templates.size(); ++t) {
          const std::vector<std::ptrdiff_t>& sources = templates[t].sources;
          sumResponses(row + x0, sources.data(), sources.size(), n, sums);
          const auto ti = static_cast<std::int32_t>(t);
          for (int k = 0; k < n; k += 8) {
            cv::v_int16x8 v = cv::v_load_aligned(sums + k);
            if (global) v = cv::v_reinterpret_as_s16(cv::v_abs(v));
            // Improvements become rare after the first templates: test 8 pixels at once (the
            // second is never above the best).
            if (!cv::v_check_any(v > cv::v_load(secondRow + x0 + k))) continue;
            cv::v_store_aligned(sums + k, v);
            for (int j = x0 + k; j < x0 + k + 8; ++j) {
              const std::int16_t u = sums[j - x0];
              if (u <= secondRow[j]) continue;
              const bool apart = bestIdx[j] >= 0 && steps.apart(ti, bestIdx[j]);
              if (u > bestRow[j]) {
                if (apart) secondRow[j] = bestRow[j], secondIdx[j] = bestIdx[j];
                bestRow[j] = u, bestIdx[j] = ti;
              } else if (apart) {
                secondRow[j] = u, secondIdx[j] = ti;
              }
            }
          }
        }
      }
    }
  };
  inStripes(work);

  // Candidates. The maxima over position (whatever the angle), as far as they reach `threshold`:
  // the pixels' bests that are maxima of their 3x3 neighbourhood, strongest first, each kept where
  // no kept one lies within kPeakReach pixels (greedy suppression) and no best that close lies
  // more than kPeakMargin above it. Keeping only the bests that no best that close beats lost parts
  // on periodic patterns: on a chessboard seen at 1/16 the part's pixel (0.75) lay on a ridge
  // rising to a neighbouring square's peak (0.84, 3 px away) and was suppressed by the ridge's next
  // pixel (0.76), which that peak suppressed in turn; a part scoring 0.999 was missed and the
  // square returned at 0.76. Those maxima are all kept here too.
  //
  // Where the score has two peaks in angle, the part's can be the lower one, or lie beside a
  // neighbour's higher peak at another angle: an entry (a pixel's best or second) is a candidate
  // too where no entry within kPeakReach pixels and kApartSteps angle steps is higher (a maximum
  // over position and angle), it reaches `separateThreshold`, and it lies within kPeakMargin of the
  // best within kPeakReach pixels: only such a peak could still be the part's (as the finish picks
  // among a part's alternatives). On a texture every pixel's best angle differs from its
  // neighbours'; the maxima over position and angle alone were three times as many candidates as
  // those over position.
  const auto peakMargin = static_cast<int>(std::lround(kPeakMargin * norm));
  const auto separateSum =
      static_cast<std::int16_t>(std::min(32767.0, std::max(threshold, separateThreshold) * norm));
  const std::array<const std::int16_t*, 2> value{best.data(), second.data()};
  const std::array<const std::int32_t*, 2> index{bestTemplate.data(), secondTemplate.data()};
  // Calls f(dx, dy, offset) for the pixels within `reach` of (x, y), until it returns false.
  // Offsets index the per-pixel arrays (rows of paddedW).
  auto forNeighbours = [&](int x, int y, auto f, int reach = kPeakReach) {
    for (int dy = -reach; dy <= reach; ++dy)
      for (int dx = -reach; dx <= reach; ++dx) {
        const int xx = x + dx, yy = y + dy;
        if (xx < 0 || yy < 0 || xx >= w || yy >= h) continue;
        if (!f(dx, dy, static_cast<std::size_t>(yy) * paddedW + xx)) return false;
      }
    return true;
  };
  // Whether `v` lies within kPeakMargin of every best within kPeakReach of (x, y): only such a peak
  // could still be the part's beside a higher one.
  auto nearTheBest = [&](int x, int y, int v) {
    return forNeighbours(x, y, [&](int, int, auto n) { return v >= best[n] - peakMargin; });
  };
  std::vector<std::uint8_t> positionMax(best.size(), 0);
  {
    struct Peak {
      int x, y;
      std::int16_t v;
    };
    std::vector<Peak> peaks;
    for (int y = 0; y < h; ++y)
      for (int x = 0; x < w; ++x) {
        const std::int16_t v = best[static_cast<std::size_t>(y) * paddedW + x];
        if (v < minSum || v <= 0) continue;
        // Strict on one side so that a plateau yields one maximum.
        const bool localMax = forNeighbours(
            x, y,
            [&](int dx, int dy, auto n) {
              const std::int16_t u = best[n];
              return (dx == 0 && dy == 0) ||
                     !(u > v || (u == v && (dy < 0 || (dy == 0 && dx < 0))));
            },
            1);
        if (localMax) peaks.push_back({x, y, v});
      }
    // Equal scores in raster order, as the strict side above.
    std::stable_sort(peaks.begin(), peaks.end(),
                     [](const Peak& a, const Peak& b) { return a.v > b.v; });
    for (const Peak& p : peaks) {
      const bool free = forNeighbours(p.x, p.y, [&](int, int, auto n) { return !positionMax[n]; });
      // A maximum that no best within kPeakReach beats is always near the best.
      if (free && nearTheBest(p.x, p.y, p.v))
        positionMax[static_cast<std::size_t>(p.y) * paddedW + p.x] = 1;
    }
  }
  std::vector<Candidate> candidates;
  for (int y = 0; y < h; ++y) {
    for (int x = 0; x < w; ++x) {
      const std::size_t at = static_cast<std::size_t>(y) * paddedW + x;
      for (int layer = 0; layer < 2; ++layer) {
        const std::int16_t v = value[layer][at];
        if (v < minSum || v <= 0) continue;
        const std::int32_t t = index[layer][at];
        if (layer != 0 || !positionMax[at]) {
          if (v < separateSum || !nearTheBest(x, y, v)) continue;
          const bool poseMax = forNeighbours(x, y, [&](int dx, int dy, auto n) {
            for (int other = 0; other < 2; ++other) {
              if (dx == 0 && dy == 0 && other == layer) continue;
              const std::int16_t u = value[other][n];
              if (u < v || index[other][n] < 0 || steps.apart(t, index[other][n])) continue;
              if (u > v || dy < 0 || (dy == 0 && (dx < 0 || (dx == 0 && other < layer))))
                return false;
            }
            return true;
          });
          if (!poseMax) continue;
        }
        const TopTemplate& tpl = templates[static_cast<std::size_t>(t)];
        candidates.push_back({double(x), double(y), tpl.angle, tpl.scale, v / norm});
      }
    }
  }
  std::sort(candidates.begin(), candidates.end(),
            [](const Candidate& a, const Candidate& b) { return a.score > b.score; });
  return candidates;
}

}  // namespace facet::shape_detail
