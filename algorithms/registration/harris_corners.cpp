#include "algorithms/registration/harris_corners.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <vector>

#include <opencv2/imgproc.hpp>

namespace facet {
namespace {

// Scale-normalised second-moment matrix entries and the Laplacian at one scale of an octave.
struct ScaleLevel {
  cv::Mat harris;     // det - k trace^2
  cv::Mat laplacian;  // sigma^2 (Ixx + Iyy), for the characteristic-scale test
  double sigma = 1;   // integration sigma at the octave's resolution
};

// The images of a detection, kept by the thread from call to call in numbered slots, each a
// view of a buffer that grows to the largest size asked for. A level of a 1280x1024 frame passes
// through about twenty full-size float images; allocated afresh, each was handed back to the
// system after the level and its pages faulted in again on the next use (a registration of such
// a frame allocated 440 MB and spent most of its 470 ms in page faults on this machine). The
// buffers stay with the thread: about 100 MB for a 1280x1024 frame, what one detection needs.
// A thread keeps at most kKeptImageBytes; an image that would take it beyond is the caller's
// own, allocated afresh (a 4096x3000 frame would keep about 1 GB a thread, and a daemon's
// stations each have one).
class KeptImages {
 public:
  cv::Mat view(std::size_t slot, cv::Size size, int type) {
    if (buffers_.size() <= slot) buffers_.resize(slot + 1);
    cv::Mat& b = buffers_[slot];
    if (b.type() == type && b.cols >= size.width && b.rows >= size.height)
      return b(cv::Rect(cv::Point(), size));
    const cv::Size grown(std::max(b.cols, size.width), std::max(b.rows, size.height));
    const std::size_t bytes = static_cast<std::size_t>(grown.area()) * CV_ELEM_SIZE(type);
    if (bytes > kKeptImageBytes - (total_ - bytesOf(b))) return cv::Mat(size, type);
    total_ -= bytesOf(b);
    b.create(grown, type);
    total_ += bytes;
    return b(cv::Rect(cv::Point(), size));
  }
  std::size_t bytes() const { return total_; }

 private:
  static std::size_t bytesOf(const cv::Mat& m) { return m.empty() ? 0 : m.total() * m.elemSize(); }
  std::vector<cv::Mat> buffers_;
  std::size_t total_ = 0;
};

KeptImages& keptImages() {
  thread_local KeptImages kept;
  return kept;
}

// Slots of keptImages(): a level's intermediates, then each level's outputs (harris, laplacian).
enum Slot : std::size_t { kSmooth, kIx, kIy, kProducts, kBlurred, kFirstOutput };

// `level`: which outputs' slots this level's harris and laplacian take (one per level that lives
// at the same time as the others of a detection).
ScaleLevel computeLevel(const cv::Mat& img, double relScale, const HarrisParams& p,
                        std::size_t level) {
  const double sd = p.derivationSigma * relScale;
  const double si = p.integrationSigma * relScale;
  KeptImages& kept = keptImages();
  const cv::Size size = img.size();
  cv::Mat smooth = kept.view(kSmooth, size, CV_32F), ix = kept.view(kIx, size, CV_32F),
          iy = kept.view(kIy, size, CV_32F), products = kept.view(kProducts, size, CV_32FC3),
          blurred = kept.view(kBlurred, size, CV_32FC3);
  // A kept view may lie inside a larger buffer: filters read it as an image of its own
  // (BORDER_ISOLATED), not the pixels an earlier, larger image left beyond its edges.
  constexpr int kOwnBorder = cv::BORDER_REFLECT | cv::BORDER_ISOLATED;
  cv::GaussianBlur(img, smooth, cv::Size(), sd, sd, cv::BORDER_REFLECT);
  cv::Sobel(smooth, ix, CV_32F, 1, 0, 3, 0.125 * sd, 0, kOwnBorder);
  cv::Sobel(smooth, iy, CV_32F, 0, 1, 3, 0.125 * sd, 0, kOwnBorder);
  // The three products are smoothed as one 3-channel image (one filter pass).
  for (int y = 0; y < size.height; ++y) {
    const float* gx = ix.ptr<float>(y);
    const float* gy = iy.ptr<float>(y);
    auto* out = products.ptr<cv::Vec3f>(y);
    for (int x = 0; x < size.width; ++x) out[x] = {gx[x] * gx[x], gy[x] * gy[x], gx[x] * gy[x]};
  }
  cv::GaussianBlur(products, blurred, cv::Size(), si, si, kOwnBorder);
  ScaleLevel out;
  out.sigma = si;
  out.harris = kept.view(kFirstOutput + 2 * level, size, CV_32F);
  const auto k = static_cast<float>(p.k);
  for (int y = 0; y < size.height; ++y) {
    const auto* m = blurred.ptr<cv::Vec3f>(y);
    auto* r = out.harris.ptr<float>(y);
    for (int x = 0; x < size.width; ++x) {
      const float ixx = m[x][0], iyy = m[x][1], ixy = m[x][2];
      const float trace = ixx + iyy;
      r[x] = ixx * iyy - ixy * ixy - k * (trace * trace);
    }
  }
  // The scale-normalised Laplacian at the integration scale picks the characteristic scale
  // (Harris-Laplace).
  if (p.selectScale) {
    cv::GaussianBlur(img, smooth, cv::Size(), si, si, cv::BORDER_REFLECT);
    out.laplacian = kept.view(kFirstOutput + 2 * level + 1, size, CV_32F);
    cv::Laplacian(smooth, out.laplacian, CV_32F, 3, si * si, 0, kOwnBorder);
  }
  return out;
}

// Offset of the peak of a parabola through (-1, a), (0, b), (1, c).
double parabolaPeak(float a, float b, float c) {
  const double d = a - 2.0 * b + c;
  if (d >= 0) return 0.0;
  return std::clamp(0.5 * (a - c) / d, -0.5, 0.5);
}

// The Laplacian of a neighbouring scale, possibly stored at another octave's resolution:
// `shift` +1 = a finer octave (coordinates x2), -1 = a coarser one (coordinates /2).
struct Neighbour {
  const cv::Mat* laplacian = nullptr;
  int shift = 0;
  [[nodiscard]] float at(int x, int y) const {
    if (shift > 0) {
      x *= 2;
      y *= 2;
    } else if (shift < 0) {
      x /= 2;
      y /= 2;
    }
    x = std::clamp(x, 0, laplacian->cols - 1);
    y = std::clamp(y, 0, laplacian->rows - 1);
    return std::abs(laplacian->at<float>(y, x));
  }
};

void detectAtLevel(const Neighbour& below, const ScaleLevel& level, const Neighbour& above,
                   double factor, int levelIndex, const HarrisParams& p,
                   std::vector<HarrisCorner>& out) {
  const cv::Mat& r = level.harris;
  double maxResponse = 0;
  cv::minMaxLoc(r, nullptr, &maxResponse);
  const float threshold =
      static_cast<float>(std::max(p.absoluteThreshold, p.relativeThreshold * maxResponse));
  const int b = std::max(p.border, 2);
  const auto plateau = static_cast<float>(p.scalePlateau);
  for (int y = b; y < r.rows - b; ++y) {
    const float* r0 = r.ptr<float>(y - 1);
    const float* r1 = r.ptr<float>(y);
    const float* r2 = r.ptr<float>(y + 1);
    for (int x = b; x < r.cols - b; ++x) {
      const float v = r1[x];
      if (v <= threshold) continue;
      if (v <= r1[x - 1] || v < r1[x + 1] || v <= r0[x - 1] || v <= r0[x] || v <= r0[x + 1] ||
          v < r2[x - 1] || v < r2[x] || v < r2[x + 1])
        continue;
      // Characteristic scale: |Laplacian| must not be clearly smaller than at the neighbouring
      // scales (HarrisParams::scalePlateau).
      if (p.selectScale) {
        const float lap = std::abs(level.laplacian.at<float>(y, x)) / plateau;
        if (lap < below.at(x, y) || lap < above.at(x, y)) continue;
      }
      const double dx = parabolaPeak(r1[x - 1], v, r1[x + 1]);
      const double dy = parabolaPeak(r0[x], v, r2[x]);
      HarrisCorner c;
      c.pt = {(x + dx) * factor, (y + dy) * factor};
      c.scale = level.sigma * factor;
      c.response = v;
      c.level = levelIndex;
      out.push_back(c);
    }
  }
}

}  // namespace

std::size_t keptCornerImageBytes() {
  return keptImages().bytes();
}

std::vector<HarrisCorner> spreadCorners(const std::vector<HarrisCorner>& corners, int count,
                                        double robustness) {
  if (static_cast<int>(corners.size()) <= count) return corners;
  std::vector<HarrisCorner> sorted = corners;
  std::sort(sorted.begin(), sorted.end(),
            [](const HarrisCorner& a, const HarrisCorner& b) { return a.response > b.response; });
  // Suppression radius: distance to the nearest clearly stronger corner of a similar scale
  // (corners of very different scale describe different structures and do not suppress).
  std::vector<double> radius2(sorted.size(), std::numeric_limits<double>::infinity());
  for (std::size_t i = 1; i < sorted.size(); ++i) {
    const HarrisCorner& c = sorted[i];
    double best = std::numeric_limits<double>::infinity();
    for (std::size_t j = 0; j < i; ++j) {
      const HarrisCorner& s = sorted[j];
      if (s.response * robustness <= c.response) break;  // sorted: no stronger ones follow
      const double ratio = s.scale / c.scale;
      if (ratio > 2.0 || ratio < 0.5) continue;
      const double dx = s.pt.x - c.pt.x, dy = s.pt.y - c.pt.y;
      best = std::min(best, dx * dx + dy * dy);
    }
    radius2[i] = best;
  }
  std::vector<std::size_t> order(sorted.size());
  for (std::size_t i = 0; i < order.size(); ++i) order[i] = i;
  std::stable_sort(order.begin(), order.end(),
                   [&](std::size_t a, std::size_t b) { return radius2[a] > radius2[b]; });
  std::vector<HarrisCorner> kept;
  kept.reserve(count);
  for (int i = 0; i < count; ++i) kept.push_back(sorted[order[i]]);
  return kept;
}

std::vector<HarrisCorner> detectHarrisGrid(const cv::Mat& grey, int cell,
                                           const HarrisParams& params) {
  CV_Assert(grey.type() == CV_32F && cell > 0);
  HarrisParams p = params;
  p.selectScale = false;
  const ScaleLevel level = computeLevel(grey, 1.0, p, 0);
  double maxResponse = 0;
  cv::minMaxLoc(level.harris, nullptr, &maxResponse);
  const double threshold = std::max(p.absoluteThreshold, p.relativeThreshold * maxResponse);
  std::vector<HarrisCorner> out;
  const int b = std::max(p.border, 2);
  for (int y0 = b; y0 < grey.rows - b; y0 += cell)
    for (int x0 = b; x0 < grey.cols - b; x0 += cell) {
      const cv::Rect r(x0, y0, std::min(cell, grey.cols - b - x0),
                       std::min(cell, grey.rows - b - y0));
      double best = 0;
      cv::Point loc;
      cv::minMaxLoc(level.harris(r), nullptr, &best, nullptr, &loc);
      if (best <= threshold) continue;
      HarrisCorner c;
      c.pt = {static_cast<double>(x0 + loc.x), static_cast<double>(y0 + loc.y)};
      c.scale = level.sigma;
      c.response = best;
      out.push_back(c);
    }
  return out;
}

std::vector<HarrisCorner> detectHarrisCorners(const cv::Mat& grey, const HarrisParams& params) {
  CV_Assert(grey.type() == CV_32F);
  CV_Assert(params.scalePlateau > 0 && params.scalePlateau <= 1);
  std::vector<HarrisCorner> all;
  const int L = std::max(1, params.levelsPerOctave);
  auto relScale = [L](int j) { return std::pow(2.0, double(j) / L); };
  // Levels 0..L-1 of every octave. Level L of octave o has the scale of level 0 of octave o+1
  // and level -1 that of level L-1 of octave o-1, so the scale test reads its neighbours there;
  // only the finest and the coarsest ends need an extra level.
  std::vector<std::vector<ScaleLevel>> octaves;
  cv::Mat octave = grey;
  for (int o = 0; o < params.octaves; ++o) {
    if (std::min(octave.rows, octave.cols) < 2 * params.border + 8) break;
    std::vector<ScaleLevel> levels;
    for (int j = 0; j < L; ++j)
      levels.push_back(computeLevel(octave, relScale(j), params, o * L + j));
    octaves.push_back(std::move(levels));
    if (o + 1 < params.octaves) {
      cv::Mat next;
      cv::pyrDown(octave, next);
      octave = next;
    }
  }
  if (octaves.empty()) return {};
  ScaleLevel finest, coarsest;
  if (params.selectScale) {
    finest = computeLevel(grey, relScale(-1), params, octaves.size() * L);
    cv::Mat last = grey;
    for (std::size_t o = 1; o < octaves.size(); ++o) {
      cv::Mat next;
      cv::pyrDown(last, next);
      last = next;
    }
    coarsest = computeLevel(last, relScale(L), params, octaves.size() * L + 1);
  }
  for (std::size_t o = 0; o < octaves.size(); ++o) {
    const double factor = std::ldexp(1.0, static_cast<int>(o));
    for (int j = 0; j < L; ++j) {
      Neighbour below, above;
      if (params.selectScale) {
        if (j > 0)
          below = {&octaves[o][j - 1].laplacian, 0};
        else if (o > 0)
          below = {&octaves[o - 1][L - 1].laplacian, +1};
        else
          below = {&finest.laplacian, 0};
        if (j + 1 < L)
          above = {&octaves[o][j + 1].laplacian, 0};
        else if (o + 1 < octaves.size())
          above = {&octaves[o + 1][0].laplacian, -1};
        else
          above = {&coarsest.laplacian, 0};
      }
      detectAtLevel(below, octaves[o][j], above, factor, static_cast<int>(o) * L + j, params, all);
    }
  }
  // Keep a pool of the strongest before the quadratic-time spreading.
  const std::size_t pool =
      std::min<std::size_t>(static_cast<std::size_t>(params.maxCorners) * 6,
                            static_cast<std::size_t>(params.maxCorners) + 4000);
  if (all.size() > pool) {
    std::nth_element(
        all.begin(), all.begin() + pool, all.end(),
        [](const HarrisCorner& a, const HarrisCorner& b) { return a.response > b.response; });
    all.resize(pool);
  }
  return spreadCorners(all, params.maxCorners, params.anmsRobustness);
}

}  // namespace facet
