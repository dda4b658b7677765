#include "algorithms/measure/grey_profile.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace facet {
namespace {

// Bilinear grey at p; false when p lies outside the pixel centres' hull.
template <class T>
bool bilinear(const cv::Mat& image, cv::Point2d p, double& grey) {
  if (!(p.x >= 0.0 && p.y >= 0.0 && p.x <= image.cols - 1 && p.y <= image.rows - 1)) return false;
  const int x0 = std::min(static_cast<int>(p.x), image.cols - 2 < 0 ? 0 : image.cols - 2);
  const int y0 = std::min(static_cast<int>(p.y), image.rows - 2 < 0 ? 0 : image.rows - 2);
  const int x1 = std::min(x0 + 1, image.cols - 1), y1 = std::min(y0 + 1, image.rows - 1);
  const double fx = p.x - x0, fy = p.y - y0;
  const T* r0 = image.ptr<T>(y0);
  const T* r1 = image.ptr<T>(y1);
  const double top = r0[x0] + fx * (r0[x1] - r0[x0]);
  const double bottom = r1[x0] + fx * (r1[x1] - r1[x0]);
  grey = top + fy * (bottom - top);
  return true;
}

template <class T>
GreyProfile sample(const cv::Mat& image, const MeasuringPath& path, const GreyProfileParams& prm,
                   double scale) {
  GreyProfile profile;
  profile.step = prm.step;
  const int n = static_cast<int>(std::floor(path.length() / prm.step + 1e-9)) + 1;
  const int lines = std::max(1, static_cast<int>(std::ceil(path.width() / prm.crossStep - 1e-9)));
  const double start = -(n - 1) * prm.step / 2.0;
  std::vector<double> values(n, 0.0);
  std::vector<char> inside(n, 0);
  bool anyMissing = false;
  for (int i = 0; i < n; ++i) {
    const double s = start + i * prm.step;
    const cv::Point2d origin = path.at(s, 0.0), across = path.acrossAt(s);
    double sum = 0;
    int count = 0;
    for (int k = 0; k < lines; ++k) {
      const double t = -path.width() / 2.0 + (k + 0.5) * path.width() / lines;
      double g = 0;
      if (bilinear<T>(image, origin + t * across, g)) sum += g, ++count;
    }
    anyMissing = anyMissing || count < lines;
    if (2 * count >= lines && count > 0) values[i] = sum * scale / count, inside[i] = 1;
  }
  // The longest run of inside positions.
  int bestBegin = 0, bestLength = 0;
  for (int i = 0; i < n;) {
    if (!inside[i]) {
      ++i;
      continue;
    }
    int j = i;
    while (j < n && inside[j]) ++j;
    if (j - i > bestLength) bestBegin = i, bestLength = j - i;
    i = j;
  }
  if (bestLength < 2) return profile;
  profile.values.assign(values.begin() + bestBegin, values.begin() + bestBegin + bestLength);
  profile.start = start + bestBegin * prm.step;
  profile.partial = anyMissing || bestLength < n;
  return profile;
}

}  // namespace

GreyProfile sampleGreyProfile(const cv::Mat& image, const MeasuringPath& path,
                              const GreyProfileParams& params) {
  if (image.type() != CV_8UC1 && image.type() != CV_16UC1)
    throw std::invalid_argument("grey profile: the image must be 8-bit or 16-bit grey");
  if (!(params.step > 0) || !(params.crossStep > 0))
    throw std::invalid_argument("grey profile: sampling steps must be positive");
  if (image.empty() || !(path.length() > 0) || !(path.width() > 0)) return {};
  return image.depth() == CV_8U ? sample<std::uint8_t>(image, path, params, 1.0)
                                : sample<std::uint16_t>(image, path, params, 1.0 / 256.0);
}

}  // namespace facet
