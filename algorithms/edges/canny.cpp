#include "algorithms/edges/canny.hpp"

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <stdexcept>
#include <type_traits>
#include <vector>

#include <opencv2/core/hal/intrin.hpp>

namespace facet {
namespace {

// 5x5 Sobel gain: binomial [1 4 6 4 1] sums to 16, the derivative [-1 -2 0 2 1] gives 8 per unit
// slope, so a ramp of one grey level per pixel reads 128.
constexpr double kSobelGain = 128.0;

void requireGreyImage(const cv::Mat& image) {
  if (image.empty()) throw std::invalid_argument("edges: the image is empty");
  if (image.type() != CV_8UC1 && image.type() != CV_16UC1)
    throw std::invalid_argument("edges: expected an 8-bit or 16-bit single-channel image, got " +
                                cv::typeToString(image.type()));
}

// Non-maximum suppression along the image axis nearest to the gradient, on the pixels
// xBegin <= x < xEnd of row y (coordinates of the gradient's area, whose maps start at row
// gradientRow0 of it). Ties are broken towards the left/upper pixel so that a plateau of two equal
// magnitudes yields one pixel. state: 0 = no, 1 = candidate, 2 = edge.
template <typename T>
void suppressRow(const EdgeGradient& g, float low, float high, const uchar* mask, int y, int xBegin,
                 int xEnd, int gradientRow0, cv::Mat& state, std::vector<cv::Point>& strong) {
  // Signed: m[x - step] with an unsigned step wraps around before the pointer addition, which is
  // undefined behaviour (UBSan's pointer-overflow check) even though it lands on the row above.
  const auto step = static_cast<std::ptrdiff_t>(g.magnitude.step1());
  const int gy0 = y - gradientRow0;  // the gradient maps may cover a strip only
  const float* m = g.magnitude.ptr<float>(gy0);
  const T* gx = g.gx.ptr<T>(gy0);
  const T* gy = g.gy.ptr<T>(gy0);
  uchar* s = state.ptr<uchar>(y);
  const auto visit = [&](int x) {
    const float v = m[x];
    if (v < low || (mask && !mask[x])) return;
    const bool horizontal = std::abs(gx[x]) >= std::abs(gy[x]);
    const float before = horizontal ? m[x - 1] : m[x - step];
    const float after = horizontal ? m[x + 1] : m[x + step];
    if (!(v > before && v >= after)) return;
    s[x] = 1;
    if (v >= high) {
      s[x] = 2;
      strong.emplace_back(x, y);
    }
  };
  // Most pixels lie below `low` (flat areas, noise): one comparison of four magnitudes passes
  // over them, and only groups with a candidate are visited pixel by pixel.
  const cv::v_float32x4 lowLanes = cv::v_setall_f32(low);
  int x = xBegin;
  for (; x + 4 <= xEnd; x += 4) {
    if (!cv::v_check_any(cv::v_load(m + x) >= lowLanes)) continue;
    for (int i = x; i < x + 4; ++i) visit(i);
  }
  for (; x < xEnd; ++x) visit(x);
}

template <typename T>
void suppress(const EdgeGradient& g, float low, float high, const cv::Mat& mask, cv::Rect area,
              int gradientRow0, cv::Mat& state, std::vector<cv::Point>& strong) {
  for (int y = area.y; y < area.y + area.height; ++y)
    suppressRow<T>(g, low, high, mask.empty() ? nullptr : mask.ptr<uchar>(y), y, area.x,
                   area.x + area.width, gradientRow0, state, strong);
}

// The vertical passes of one run's columns: smooth[i] and deriv[i] for column first + i,
// i < n. Columns outside the image repeat the border column; only a run's ends can reach
// outside, so the middle needs no clamp and vectorises.
// Column (a..e top to bottom) -> its 5-tap smoothing and derivative sums.
template <typename S>
inline void verticalTaps(int a, int b, int c, int d, int e, S& smooth, S& deriv) {
  smooth = static_cast<S>(a + 4 * b + 6 * c + 4 * d + e);
  deriv = static_cast<S>(e - a + 2 * (d - b));
}

template <typename T, typename S>
void verticalPasses(const T* const (&r)[5], int first, int n, int cols, S* __restrict smooth,
                    S* __restrict deriv) {
  auto column = [&](int i, int x) {
    verticalTaps(r[0][x], r[1][x], r[2][x], r[3][x], r[4][x], smooth[i], deriv[i]);
  };
  int i = 0;
  for (; i < n && first + i < 0; ++i) column(i, 0);
  const int middle = std::clamp(cols - first, i, n) - i;
  const T* __restrict r0 = r[0] + first + i;
  const T* __restrict r1 = r[1] + first + i;
  const T* __restrict r2 = r[2] + first + i;
  const T* __restrict r3 = r[3] + first + i;
  const T* __restrict r4 = r[4] + first + i;
  S* __restrict s = smooth + i;
  S* __restrict t = deriv + i;
  for (int k = 0; k < middle; ++k) verticalTaps(r0[k], r1[k], r2[k], r3[k], r4[k], s[k], t[k]);
  for (i += middle; i < n; ++i) column(i, cols - 1);
}

// The horizontal passes of one run of n pixels from the vertical ones (s[k], d[k] for the
// run's columns from two before its first pixel on): derivatives and magnitude. Distinct
// arrays (__restrict), so that the loop vectorises.
template <typename S, typename D>
void horizontalPasses(const S* __restrict s, const S* __restrict d, int n, float scale,
                      D* __restrict gx, D* __restrict gy, float* __restrict mag) {
  for (int i = 0; i < n; ++i) {
    const int k = i + 2;
    gx[i] = static_cast<D>(s[k + 2] - s[k - 2] + 2 * (s[k + 1] - s[k - 1]));
    gy[i] = static_cast<D>(d[k - 2] + 4 * d[k - 1] + 6 * d[k] + 4 * d[k + 1] + d[k + 2]);
    const float fa = static_cast<float>(gx[i]), fb = static_cast<float>(gy[i]);
    mag[i] = scale * std::sqrt(fa * fa + fb * fb);
  }
}

// The 5x5 Sobel derivatives and the magnitude at the pixels of `runs` (image coordinates, inside
// g.area), separably: the vertical passes of the run's columns (two more either side), then the
// horizontal ones. Integer sums, so equal to cv::Sobel's (CV_16S for 8-bit input; CV_32F for
// 16-bit input, exact there too: every partial sum stays below 2^24). The image border is
// replicated, as computeEdgeGradient does. On 8-bit images every sum fits 16 bits (smoothing at
// most 16 x 255, derivatives at most 3 x 16 x 255 = 12240 in magnitude): the passes then work on
// eight pixels per register instead of four, with the same values.
template <typename T, typename D>
void gradientOnRuns(const cv::Mat& image, const RowRuns& runs, EdgeGradient& g) {
  using Sum = std::conditional_t<sizeof(T) == 1, std::int16_t, int>;
  const float scale = static_cast<float>(g.scale);
  std::vector<Sum> smooth, deriv;
  for (const RowRun& run : runs) {
    if (run.x0 >= run.x1) continue;
    const T* r[5];
    for (int j = 0; j < 5; ++j) r[j] = image.ptr<T>(std::clamp(run.y - 2 + j, 0, image.rows - 1));
    const int n = run.x1 - run.x0 + 4;
    smooth.resize(n);
    deriv.resize(n);
    verticalPasses<T, Sum>(r, run.x0 - 2, n, image.cols, smooth.data(), deriv.data());
    const int row = run.y - g.area.y, x0 = run.x0 - g.area.x;
    horizontalPasses<Sum, D>(smooth.data(), deriv.data(), run.x1 - run.x0, scale,
                             g.gx.ptr<D>(row) + x0, g.gy.ptr<D>(row) + x0,
                             g.magnitude.ptr<float>(row) + x0);
  }
}

// Hysteresis: grow the strong pixels through 8-connected candidates (state 0 on the border, so
// the neighbours are always inside), then 2 -> 255 and everything else -> 0.
void hysteresis(cv::Mat& state, std::vector<cv::Point>& stack) {
  while (!stack.empty()) {
    const cv::Point p = stack.back();
    stack.pop_back();
    for (int dy = -1; dy <= 1; ++dy) {
      auto* s = state.ptr<uchar>(p.y + dy);
      for (int dx = -1; dx <= 1; ++dx) {
        if (s[p.x + dx] == 1) {
          s[p.x + dx] = 2;
          stack.emplace_back(p.x + dx, p.y + dy);
        }
      }
    }
  }
  cv::compare(state, 2, state, cv::CMP_EQ);
}

cv::Rect candidateArea(cv::Size size, cv::Rect candidates) {
  const cv::Rect inside(1, 1, size.width - 2, size.height - 2);
  return candidates.empty() ? cv::Rect(2, 2, size.width - 4, size.height - 4) & inside
                            : candidates & inside;
}

// The gradient of a strip of image rows that moves down the image: the rows a strip shares with
// the previous one (suppression reads one row above and below each strip, so two) are moved up
// in the maps instead of being computed again. Maps of `capacity` rows, allocated once.
class StripGradient {
 public:
  StripGradient(const cv::Mat& image, int x, int width, int capacity) : image_(image) {
    const bool eightBit = image.depth() == CV_8U;
    g_.scale = (eightBit ? 1.0 : 1.0 / 256.0) / kSobelGain;
    const int type = eightBit ? CV_16S : CV_32F;
    g_.gx.create(capacity, width, type);
    g_.gy.create(capacity, width, type);
    g_.magnitude.create(capacity, width, CV_32F);
    g_.area = cv::Rect(x, 0, width, 0);
  }

  // The gradient of image rows y .. y + count - 1 (at most the capacity; y not above the
  // previous strip's first row), in the maps' first `count` rows.
  const EdgeGradient& rows(int y, int count) {
    cv::Rect& area = g_.area;
    const int shared = std::clamp(area.y + area.height - y, 0, area.height);
    for (cv::Mat* map : {&g_.gx, &g_.gy, &g_.magnitude})
      for (int i = 0; i < shared; ++i) map->row(area.height - shared + i).copyTo(map->row(i));
    area.y = y;
    area.height = count;
    runs_.clear();
    for (int i = shared; i < count; ++i) runs_.push_back({y + i, area.x, area.br().x});
    if (image_.depth() == CV_8U)
      gradientOnRuns<uchar, short>(image_, runs_, g_);
    else
      gradientOnRuns<ushort, float>(image_, runs_, g_);
    return g_;
  }

 private:
  const cv::Mat& image_;
  EdgeGradient g_;
  RowRuns runs_;
};

}  // namespace

EdgeGradient computeEdgeGradient(const cv::Mat& image, cv::Rect area) {
  requireGreyImage(image);
  const cv::Rect full(0, 0, image.cols, image.rows);
  area = area.empty() ? full : (area & full);
  EdgeGradient g;
  g.area = area;
  if (area.empty()) return g;
  const bool eightBit = image.depth() == CV_8U;
  g.scale = (eightBit ? 1.0 : 1.0 / 256.0) / kSobelGain;
  const int type = eightBit ? CV_16S : CV_32F;
  g.gx.create(area.size(), type);
  g.gy.create(area.size(), type);
  g.magnitude.create(area.size(), CV_32F);
  // The area's rows as runs: the separable passes read the real pixels around the area and
  // replicate the image's border, as cv::Sobel on the image with BORDER_REPLICATE does, and cost
  // a fraction of its two filter calls on the small strips Canny works in.
  RowRuns rows(static_cast<std::size_t>(area.height));
  for (int i = 0; i < area.height; ++i)
    rows[static_cast<std::size_t>(i)] = {area.y + i, area.x, area.br().x};
  if (eightBit)
    gradientOnRuns<uchar, short>(image, rows, g);
  else
    gradientOnRuns<ushort, float>(image, rows, g);
  return g;
}

EdgeGradient computeEdgeGradientOnRuns(const cv::Mat& image, cv::Rect area, const RowRuns& runs) {
  requireGreyImage(image);
  EdgeGradient g;
  g.area = area & cv::Rect(0, 0, image.cols, image.rows);
  if (g.area.empty()) return g;
  const bool eightBit = image.depth() == CV_8U;
  g.scale = (eightBit ? 1.0 : 1.0 / 256.0) / kSobelGain;
  const int type = eightBit ? CV_16S : CV_32F;
  g.gx.create(g.area.size(), type);
  g.gy.create(g.area.size(), type);
  g.magnitude.create(g.area.size(), CV_32F);
  const RowRuns grown = dilateRowRuns(runs, g.area);
  if (eightBit)
    gradientOnRuns<uchar, short>(image, grown, g);
  else
    gradientOnRuns<ushort, float>(image, grown, g);
  return g;
}

cv::Mat cannyOnRuns(const EdgeGradient& gradient, double low, double high, const RowRuns& runs) {
  const cv::Rect area = gradient.area;
  cv::Mat state = cv::Mat::zeros(area.size(), CV_8U);
  if (area.empty()) return state;
  // One pixel inside the area: suppression and hysteresis read the neighbours.
  const cv::Rect inside(area.x + 1, area.y + 1, area.width - 2, area.height - 2);
  const auto lowF = static_cast<float>(low);
  const auto highF = static_cast<float>(std::max(low, high));
  std::vector<cv::Point> stack;
  for (const RowRun& run : runs) {
    if (run.y < inside.y || run.y >= inside.br().y) continue;
    const int x0 = std::max(run.x0, inside.x) - area.x;
    const int x1 = std::min(run.x1, inside.br().x) - area.x;
    if (gradient.gx.depth() == CV_16S)
      suppressRow<short>(gradient, lowF, highF, nullptr, run.y - area.y, x0, x1, 0, state, stack);
    else
      suppressRow<float>(gradient, lowF, highF, nullptr, run.y - area.y, x0, x1, 0, state, stack);
  }
  hysteresis(state, stack);
  return state;
}

cv::Mat cannyFromGradient(const EdgeGradient& gradient, double low, double high,
                          const cv::Mat& mask, cv::Rect candidates) {
  const cv::Size size = gradient.area.size();
  cv::Mat state = cv::Mat::zeros(size, CV_8U);
  if (size.empty()) return state;
  if (!mask.empty() && (mask.size() != size || mask.type() != CV_8UC1))
    throw std::invalid_argument("edges: the mask must be CV_8UC1 of the region's size");
  candidates = candidateArea(size, candidates);
  const auto lowF = static_cast<float>(low);
  const auto highF = static_cast<float>(std::max(low, high));
  std::vector<cv::Point> stack;
  if (gradient.gx.depth() == CV_16S)
    suppress<short>(gradient, lowF, highF, mask, candidates, 0, state, stack);
  else
    suppress<float>(gradient, lowF, highF, mask, candidates, 0, state, stack);
  hysteresis(state, stack);
  return state;
}

cv::Mat cannyInStrips(const cv::Mat& image, cv::Rect area, double low, double high,
                      const cv::Mat& mask, cv::Rect candidates) {
  requireGreyImage(image);
  area &= cv::Rect(0, 0, image.cols, image.rows);
  cv::Mat state = cv::Mat::zeros(area.size(), CV_8U);
  if (area.empty()) return state;
  if (!mask.empty() && (mask.size() != area.size() || mask.type() != CV_8UC1))
    throw std::invalid_argument("edges: the mask must be CV_8UC1 of the region's size");
  candidates = candidateArea(area.size(), candidates);
  const auto lowF = static_cast<float>(low);
  const auto highF = static_cast<float>(std::max(low, high));
  std::vector<cv::Point> stack;
  // Strips of 16 rows keep the gradient maps small (below malloc's mmap threshold, so they are
  // reused instead of being mapped and faulted in afresh for every image).
  constexpr int kStrip = 16;
  StripGradient strips(image, area.x, area.width, kStrip + 2);
  for (int r0 = candidates.y; r0 < candidates.y + candidates.height; r0 += kStrip) {
    const int r1 = std::min(r0 + kStrip, candidates.y + candidates.height);
    // Gradient rows r0 - 1 .. r1 (suppression looks one row up and down).
    const EdgeGradient& g = strips.rows(area.y + r0 - 1, r1 - r0 + 2);
    const cv::Rect rows(candidates.x, r0, candidates.width, r1 - r0);
    if (g.gx.depth() == CV_16S)
      suppress<short>(g, lowF, highF, mask, rows, r0 - 1, state, stack);
    else
      suppress<float>(g, lowF, highF, mask, rows, r0 - 1, state, stack);
  }
  hysteresis(state, stack);
  return state;
}

cv::Mat cannyEdges(const cv::Mat& image, double low, double high, cv::Rect roi,
                   const cv::Mat& mask) {
  const EdgeGradient g = computeEdgeGradient(image, roi);
  cv::Mat localMask;
  if (!mask.empty()) {
    if (mask.size() != image.size() || mask.type() != CV_8UC1)
      throw std::invalid_argument("edges: the mask must be CV_8UC1 of the image's size");
    localMask = mask(g.area);
  }
  return cannyFromGradient(g, low, high, localMask);
}

}  // namespace facet
