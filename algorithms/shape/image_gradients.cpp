#include "algorithms/shape/image_gradients.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <type_traits>
#include <vector>

#include <opencv2/core/hal/intrin.hpp>
#include <opencv2/imgproc.hpp>

#include "algorithms/shape/zeroed_mat.hpp"

namespace facet::shape_detail {

cv::Mat toGreyFloat(const cv::Mat& image) {
  if (image.channels() != 1 || (image.depth() != CV_8U && image.depth() != CV_16U))
    throw std::invalid_argument("expected an 8-bit or 16-bit single-channel image");
  cv::Mat grey;
  image.convertTo(grey, CV_32F, image.depth() == CV_16U ? 1.0 / 256.0 : 1.0);
  return grey;
}

void sobelGradients(const cv::Mat& image, cv::Mat& gx, cv::Mat& gy) {
  // The 3x3 Sobel kernel is 8 times the central difference of a [1 2 1]-smoothed image.
  cv::Sobel(image, gx, CV_32F, 1, 0, 3, 1.0 / 8.0, 0.0, cv::BORDER_REPLICATE);
  cv::Sobel(image, gy, CV_32F, 0, 1, 3, 1.0 / 8.0, 0.0, cv::BORDER_REPLICATE);
}

namespace {

// The same as the scalar loop below (the same float operations, correctly rounded in both), 16
// pixels at a time; returns the number of pixels done.
int normaliseSimd(const short* px, const short* py, int n, float min2, cv::Vec2b* o) {
  const cv::v_float32x4 lowest = cv::v_setall_f32(min2), scale = cv::v_setall_f32(127.0f);
  const cv::v_float32x4 zero = cv::v_setzero_f32();
  auto rounded = [&](const cv::v_int32x4& ia, const cv::v_int32x4& ib, cv::v_int32x4& ra,
                     cv::v_int32x4& rb) {
    const cv::v_float32x4 a = cv::v_cvt_f32(ia), b = cv::v_cvt_f32(ib);
    const cv::v_float32x4 m2 = a * a + b * b;
    const cv::v_float32x4 inv = cv::v_select(m2 >= lowest, scale / cv::v_sqrt(m2), zero);
    ra = cv::v_round(a * inv);
    rb = cv::v_round(b * inv);
  };
  int x = 0;
  for (; x + 16 <= n; x += 16) {
    cv::v_int16x8 outA[2], outB[2];
    for (int h = 0; h < 2; ++h) {
      cv::v_int32x4 a0, a1, b0, b1, ra0, ra1, rb0, rb1;
      cv::v_expand(cv::v_load(px + x + 8 * h), a0, a1);
      cv::v_expand(cv::v_load(py + x + 8 * h), b0, b1);
      rounded(a0, b0, ra0, rb0);
      rounded(a1, b1, ra1, rb1);
      outA[h] = cv::v_pack(ra0, ra1);
      outB[h] = cv::v_pack(rb0, rb1);
    }
    cv::v_store_interleave(reinterpret_cast<schar*>(o + x), cv::v_pack(outA[0], outA[1]),
                           cv::v_pack(outB[0], outB[1]));
  }
  return x;
}

// Raw Sobel responses (8 x grey levels per pixel) -> directions scaled by 127.
template <typename T>
void normalise(const cv::Mat& gx, const cv::Mat& gy, float min2, cv::Mat& out) {
  for (int y = 0; y < gx.rows; ++y) {
    const T* px = gx.ptr<T>(y);
    const T* py = gy.ptr<T>(y);
    auto* o = out.ptr<cv::Vec2b>(y);
    int x = 0;
    if constexpr (std::is_same_v<T, short>) x = normaliseSimd(px, py, gx.cols, min2, o);
    for (; x < gx.cols; ++x) {
      const float a = static_cast<float>(px[x]), b = static_cast<float>(py[x]);
      const float m2 = a * a + b * b;
      const float inv = m2 >= min2 ? 127.0f / std::sqrt(m2) : 0.0f;
      // cvRound: an inlined conversion instruction (std::lround is a library call per value).
      o[x] = {static_cast<uchar>(static_cast<signed char>(cvRound(a * inv))),
              static_cast<uchar>(static_cast<signed char>(cvRound(b * inv)))};
    }
  }
}

// The 3x3 Sobel derivatives of the pixels x0 <= x < x1 of row y of an 8-bit image, its border
// replicated: cv::Sobel's CV_16S values (integer sums, so equal), without the filter engine that
// each cv::Sobel call sets up for a few tiles. s and d are the columns' vertical passes (smoothing
// [1 2 1] and difference), from column x0 - 1 to x1.
void sobelRow(const cv::Mat& grey, int y, int x0, int x1, std::vector<int>& s, std::vector<int>& d,
              short* __restrict gx, short* __restrict gy) {
  const uchar* a = grey.ptr<uchar>(std::max(y - 1, 0));
  const uchar* b = grey.ptr<uchar>(y);
  const uchar* c = grey.ptr<uchar>(std::min(y + 1, grey.rows - 1));
  const int n = x1 - x0 + 2;
  s.resize(static_cast<std::size_t>(n));
  d.resize(static_cast<std::size_t>(n));
  int* __restrict sp = s.data();
  int* __restrict dp = d.data();
  const int lastColumn = grey.cols - 1;
  // Only the first and last columns can lie outside the image.
  const auto column = [&](int i) {
    const int x = std::clamp(x0 - 1 + i, 0, lastColumn);
    sp[i] = a[x] + 2 * b[x] + c[x];
    dp[i] = c[x] - a[x];
  };
  column(0);
  const uchar* __restrict ra = a + x0;
  const uchar* __restrict rb = b + x0;
  const uchar* __restrict rc = c + x0;
  for (int i = 1; i < n - 1; ++i) {
    sp[i] = ra[i - 1] + 2 * rb[i - 1] + rc[i - 1];
    dp[i] = rc[i - 1] - ra[i - 1];
  }
  column(n - 1);
  for (int i = 0; i < n - 2; ++i) {
    gx[i] = static_cast<short>(sp[i + 2] - sp[i]);
    gy[i] = static_cast<short>(dp[i] + 2 * dp[i + 1] + dp[i + 2]);
  }
}

// A search makes a field per pyramid level, though it computes only the tiles near its
// candidates. The thread keeps the fields of its last searches; a new field of the same size
// clears only the tiles its predecessor computed.
struct FieldBuffers {
  cv::Mat field, done;
};
constexpr std::size_t kKeptBuffers = 6;

std::vector<FieldBuffers>& keptBuffers() {
  thread_local std::vector<FieldBuffers> kept;
  return kept;
}

}  // namespace

DirectionField::DirectionField(cv::Mat grey, double minContrast)
    : grey_(std::move(grey)), minContrast_(std::max(minContrast, 1e-3)) {
  const cv::Size tiles((grey_.cols + kTile - 1) / kTile, (grey_.rows + kTile - 1) / kTile);
  std::vector<FieldBuffers>& kept = keptBuffers();
  for (auto it = kept.begin(); it != kept.end(); ++it) {
    if (it->field.size() != grey_.size()) continue;
    field_ = std::move(it->field);
    done_ = std::move(it->done);
    kept.erase(it);
    const cv::Rect image(0, 0, grey_.cols, grey_.rows);
    for (int ty = 0; ty < tiles.height; ++ty) {
      const uchar* row = done_.ptr<uchar>(ty);
      for (int tx = 0; tx < tiles.width;) {
        if (!row[tx]) {
          ++tx;
          continue;
        }
        int end = tx;
        while (end < tiles.width && row[end]) ++end;
        field_(cv::Rect(tx * kTile, ty * kTile, (end - tx) * kTile, kTile) & image)
            .setTo(cv::Scalar::all(0));
        tx = end;
      }
    }
    done_.setTo(cv::Scalar::all(0));
    return;
  }
  field_ = zeroedMat(grey_.size(), CV_8SC2);  // its pages touched only where computed
  done_ = cv::Mat(tiles, CV_8U, cv::Scalar(0));
}

DirectionField::~DirectionField() {
  // Only buffers that no copy of this field still shares.
  const auto alone = [](const cv::Mat& m) { return !m.empty() && m.u && m.u->refcount == 1; };
  if (!alone(field_) || !alone(done_)) return;
  std::vector<FieldBuffers>& kept = keptBuffers();
  if (kept.size() >= kKeptBuffers) kept.erase(kept.begin());
  kept.push_back({std::move(field_), std::move(done_)});
}

void DirectionField::ensure(cv::Rect region) {
  region &= cv::Rect(0, 0, grey_.cols, grey_.rows);
  if (region.empty()) return;
  const int tx0 = region.x / kTile, tx1 = (region.x + region.width - 1) / kTile;
  const int ty0 = region.y / kTile, ty1 = (region.y + region.height - 1) / kTile;
  // Rows of missing tiles are computed as runs, so that Sobel sees long rows.
  std::vector<int> sums, differences;
  for (int ty = ty0; ty <= ty1; ++ty) {
    for (int tx = tx0; tx <= tx1;) {
      if (done_.at<uchar>(ty, tx)) {
        ++tx;
        continue;
      }
      int end = tx;
      while (end <= tx1 && !done_.at<uchar>(ty, end)) done_.at<uchar>(ty, end++) = 1;
      const cv::Rect run = cv::Rect(tx * kTile, ty * kTile, (end - tx) * kTile, kTile) &
                           cv::Rect(0, 0, grey_.cols, grey_.rows);
      // Sobel on a view reads the real neighbours outside the run (replicated at the image edge),
      // so tiles agree with a whole-image computation.
      cv::Mat gx, gy;
      cv::Mat out = field_(run);
      if (grey_.depth() == CV_8U) {
        gx.create(run.size(), CV_16S);
        gy.create(run.size(), CV_16S);
        for (int y = 0; y < run.height; ++y)
          sobelRow(grey_, run.y + y, run.x, run.br().x, sums, differences, gx.ptr<short>(y),
                   gy.ptr<short>(y));
        normalise<short>(gx, gy, static_cast<float>(64.0 * minContrast_ * minContrast_), out);
      } else {
        cv::Sobel(grey_(run), gx, CV_32F, 1, 0, 3, 1.0, 0.0, cv::BORDER_REPLICATE);
        cv::Sobel(grey_(run), gy, CV_32F, 0, 1, 3, 1.0, 0.0, cv::BORDER_REPLICATE);
        normalise<float>(gx, gy, static_cast<float>(64.0 * minContrast_ * minContrast_), out);
      }
      tx = end;
    }
  }
}

}  // namespace facet::shape_detail
