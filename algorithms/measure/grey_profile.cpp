#include "algorithms/measure/grey_profile.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>

#include "algorithms/image/sensor_limit.hpp"

namespace facet {
namespace {

// The image as the sampling loop reads it: raw rows, and the largest top-left corner a 2x2
// interpolation cell can have (a point on the last column or row uses the cell before it).
template <class T>
struct Raster {
  explicit Raster(const cv::Mat& image)
      : data(image.data),
        stride(image.step[0]),
        maxX(image.cols - 1),
        maxY(image.rows - 1),
        lastCellX(std::max(0, image.cols - 2)),
        lastCellY(std::max(0, image.rows - 2)),
        dx(image.cols > 1 ? 1 : 0),
        dy(image.rows > 1 ? image.step[0] : 0) {}

  // Strictly inside the last cell: bilinear() needs neither its check nor its clamps.
  [[nodiscard]] bool interior(double x, double y) const {
    return x >= 0.0 && y >= 0.0 && x < maxX && y < maxY;
  }
  [[nodiscard]] double interiorBilinear(double x, double y) const {
    const int x0 = static_cast<int>(x), y0 = static_cast<int>(y);
    const double fx = x - x0, fy = y - y0;
    const T* r0 = reinterpret_cast<const T*>(data + static_cast<std::size_t>(y0) * stride) + x0;
    const T* r1 = reinterpret_cast<const T*>(reinterpret_cast<const uchar*>(r0) + stride);
    const double top = r0[0] + fx * (r0[1] - r0[0]);
    const double bottom = r1[0] + fx * (r1[1] - r1[0]);
    return top + fy * (bottom - top);
  }

  // Bilinear grey at (x, y); false when the point lies outside the pixel centres' hull.
  bool bilinear(double x, double y, double& grey) const {
    if (!(x >= 0.0 && y >= 0.0 && x <= maxX && y <= maxY)) return false;
    const int x0 = std::min(static_cast<int>(x), lastCellX);
    const int y0 = std::min(static_cast<int>(y), lastCellY);
    const double fx = x - x0, fy = y - y0;
    const T* r0 = reinterpret_cast<const T*>(data + static_cast<std::size_t>(y0) * stride) + x0;
    const T* r1 = reinterpret_cast<const T*>(reinterpret_cast<const uchar*>(r0) + dy);
    const double top = r0[0] + fx * (r0[dx] - r0[0]);
    const double bottom = r1[0] + fx * (r1[dx] - r1[0]);
    grey = top + fy * (bottom - top);
    return true;
  }

  const uchar* data;
  std::size_t stride;
  double maxX, maxY;
  int lastCellX, lastCellY;
  int dx;          // 0 for a one-column image: the cell's right neighbour is itself
  std::size_t dy;  // bytes to the cell's lower row; 0 for a one-row image
};

}  // namespace

GreyProfileSampler::GreyProfileSampler(const GreyProfileParams& params) : params_(params) {
  if (!(params.step > 0) || !(params.crossStep > 0))
    throw std::invalid_argument("grey profile: sampling steps must be positive");
}

template <class T>
void GreyProfileSampler::sampleAs(const cv::Mat& image, const MeasuringPath& path, double scale) {
  const GreyProfileParams& prm = params_;
  GreyProfile& profile = profile_;
  const int n = static_cast<int>(std::floor(path.length() / prm.step + 1e-9)) + 1;
  const int lines = std::max(1, static_cast<int>(std::ceil(path.width() / prm.crossStep - 1e-9)));
  const double start = -(n - 1) * prm.step / 2.0;
  // The cross offsets of the averaged lines, the same at every position.
  offsets_.resize(lines);
  for (int k = 0; k < lines; ++k)
    offsets_[k] = -path.width() / 2.0 + (k + 0.5) * path.width() / lines;
  const Raster<T> raster(image);
  origin_.resize(n), across_.resize(n), sums_.assign(n, 0.0);
  // The cross line is a segment: with both ends inside, every sample on it is.
  const double tFirst = offsets_.front(), tLast = offsets_.back();
  bool interior = true;
  for (int i = 0; i < n; ++i) {
    const double s = start + i * prm.step;
    const cv::Point2d o = path.at(s, 0.0), a = path.acrossAt(s);
    origin_[i] = o, across_[i] = a;
    interior = interior && raster.interior(o.x + tFirst * a.x, o.y + tFirst * a.y) &&
               raster.interior(o.x + tLast * a.x, o.y + tLast * a.y);
  }
  if (interior) {
    // Line by line: the positions' samples are independent of each other, which keeps the
    // processor's pipeline full; each position still sums its lines in the same order.
    for (const double t : offsets_)
      for (int i = 0; i < n; ++i)
        sums_[i] += raster.interiorBilinear(origin_[i].x + t * across_[i].x,
                                            origin_[i].y + t * across_[i].y);
    // Every position is whole: the profile is all of them.
    profile.step = prm.step;
    if (n < 2) return;
    profile.values.resize(n);
    for (int i = 0; i < n; ++i) profile.values[i] = sums_[i] * scale / lines;
    profile.start = start;
    return;
  }
  counts_.assign(n, 0);
  for (int i = 0; i < n; ++i)
    for (const double t : offsets_) {
      double g = 0;
      if (raster.bilinear(origin_[i].x + t * across_[i].x, origin_[i].y + t * across_[i].y, g))
        sums_[i] += g, ++counts_[i];
    }
  // A position is inside when at least half its samples are; the longest run of them is kept.
  const auto inside = [&](int i) { return 2 * counts_[i] >= lines && counts_[i] > 0; };
  bool anyMissing = false;
  for (int i = 0; i < n; ++i) {
    anyMissing = anyMissing || counts_[i] < lines;
    if (inside(i)) sums_[i] = sums_[i] * scale / counts_[i];
  }
  int bestBegin = 0, bestLength = 0;
  for (int i = 0; i < n;) {
    if (!inside(i)) {
      ++i;
      continue;
    }
    int j = i;
    while (j < n && inside(j)) ++j;
    if (j - i > bestLength) bestBegin = i, bestLength = j - i;
    i = j;
  }
  profile.step = prm.step;
  if (bestLength < 2) return;
  profile.values.assign(sums_.begin() + bestBegin, sums_.begin() + bestBegin + bestLength);
  profile.start = start + bestBegin * prm.step;
  profile.partial = anyMissing || bestLength < n;
}

const GreyProfile& GreyProfileSampler::sample(const cv::Mat& image, const MeasuringPath& path) {
  if (image.type() != CV_8UC1 && image.type() != CV_16UC1)
    throw std::invalid_argument("grey profile: the image must be 8-bit or 16-bit grey");
  // Cleared, not replaced: the values keep their capacity for the next path.
  profile_.values.clear();
  profile_.start = profile_.step = 0;
  profile_.partial = false;
  profile_.clipLevel = sensorLimit(image.depth());
  if (image.empty() || !(path.length() > 0) || !(path.width() > 0)) return profile_;
  if (image.depth() == CV_8U)
    sampleAs<std::uint8_t>(image, path, 1.0);
  else
    sampleAs<std::uint16_t>(image, path, 1.0 / 256.0);
  return profile_;
}

GreyProfile sampleGreyProfile(const cv::Mat& image, const MeasuringPath& path,
                              const GreyProfileParams& params) {
  GreyProfileSampler sampler(params);
  return sampler.sample(image, path);
}

}  // namespace facet
