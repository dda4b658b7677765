#include "algorithms/registration/harris_affine.hpp"

#include <algorithm>
#include <cmath>

#include <opencv2/imgproc.hpp>

namespace facet {
namespace {

// Samples the normalised patch p(u) = I(centre + shape * u / unit), u in [-radius, radius]^2.
bool samplePatch(const std::vector<cv::Mat>& pyramid, cv::Point2d centre, const cv::Matx22d& shape,
                 double unit, int radius, cv::Mat& patch) {
  const double spacing = std::sqrt(std::abs(cv::determinant(shape))) / unit;
  int octave = spacing > 1 ? static_cast<int>(std::floor(std::log2(spacing))) : 0;
  octave = std::clamp(octave, 0, static_cast<int>(pyramid.size()) - 1);
  const cv::Mat& img = pyramid[octave];
  const double inv = std::ldexp(1.0, -octave);
  const int size = 2 * radius + 1;
  patch.create(size, size, CV_32F);
  for (int v = -radius; v <= radius; ++v) {
    float* row = patch.ptr<float>(v + radius);
    for (int u = -radius; u <= radius; ++u) {
      const double x = (centre.x + (shape(0, 0) * u + shape(0, 1) * v) / unit) * inv;
      const double y = (centre.y + (shape(1, 0) * u + shape(1, 1) * v) / unit) * inv;
      if (x < 0 || y < 0 || x > img.cols - 1.001 || y > img.rows - 1.001) return false;
      const int x0 = static_cast<int>(x), y0 = static_cast<int>(y);
      const double fx = x - x0, fy = y - y0;
      const float* r0 = img.ptr<float>(y0);
      const float* r1 = img.ptr<float>(y0 + 1);
      row[u + radius] = static_cast<float>((1 - fy) * ((1 - fx) * r0[x0] + fx * r0[x0 + 1]) +
                                           fy * ((1 - fx) * r1[x0] + fx * r1[x0 + 1]));
    }
  }
  return true;
}

// The Gaussian-weighted second-moment matrix of a patch (derivatives at 0.7 of the window sigma),
// measured on every patch of every region with one window sigma: the window, the smoothing kernel
// and the buffers are made once. (cv::GaussianBlur would build the same kernel, in exact
// arithmetic, on each of the thousands of calls: a tenth of the work.)
class SecondMoment {
 public:
  SecondMoment(int radius, double sigma)
      : weights_(2 * radius + 1, 2 * radius + 1, CV_32F),
        // GaussianBlur's kernel for a float image: 4 sigma on each side.
        smoothing_(cv::getGaussianKernel(cvRound(0.7 * sigma * 8 + 1) | 1, 0.7 * sigma, CV_32F)) {
    for (int y = -radius; y <= radius; ++y)
      for (int x = -radius; x <= radius; ++x)
        weights_.at<float>(y + radius, x + radius) =
            static_cast<float>(std::exp(-(x * x + y * y) / (2 * sigma * sigma)));
  }

  cv::Matx22d of(const cv::Mat& patch) {
    cv::sepFilter2D(patch, smooth_, CV_32F, smoothing_, smoothing_, cv::Point(-1, -1), 0,
                    cv::BORDER_REFLECT);
    cv::Sobel(smooth_, gx_, CV_32F, 1, 0, 3);
    cv::Sobel(smooth_, gy_, CV_32F, 0, 1, 3);
    double a = 0, b = 0, c = 0;
    for (int y = 0; y < patch.rows; ++y) {
      const float* w = weights_.ptr<float>(y);
      const float* gx = gx_.ptr<float>(y);
      const float* gy = gy_.ptr<float>(y);
      for (int x = 0; x < patch.cols; ++x) {
        const double ix = gx[x], iy = gy[x];
        a += w[x] * ix * ix;
        b += w[x] * ix * iy;
        c += w[x] * iy * iy;
      }
    }
    return {a, b, b, c};
  }

 private:
  cv::Mat weights_;    // the Gaussian window of M
  cv::Mat smoothing_;  // 1D kernel of the derivatives' smoothing
  cv::Mat smooth_, gx_, gy_;
};

}  // namespace

std::vector<AffineRegion> circularRegions(const std::vector<HarrisCorner>& corners) {
  std::vector<AffineRegion> out;
  out.reserve(corners.size());
  for (const auto& c : corners)
    out.push_back({c.pt, cv::Matx22d(c.scale, 0, 0, c.scale), c.response});
  return out;
}

std::vector<AffineRegion> adaptAffineRegions(const std::vector<cv::Mat>& pyramid,
                                             const std::vector<HarrisCorner>& corners,
                                             const HarrisAffineParams& params) {
  std::vector<AffineRegion> out;
  const int radius = params.patchRadius;
  const double unit = radius / 3.0;  // one unit of the shape spans this many patch pixels
  cv::Mat patch;
  SecondMoment secondMoment(radius, unit);
  for (const HarrisCorner& c : corners) {
    cv::Matx22d shape(c.scale, 0, 0, c.scale);
    bool converged = false;
    bool lost = false;
    for (int it = 0; it < params.maxIterations && !lost; ++it) {
      if (!samplePatch(pyramid, c.pt, shape, unit, radius, patch)) {
        lost = true;
        break;
      }
      const cv::Matx22d M = secondMoment.of(patch);
      // Eigen-decomposition of the symmetric 2x2 M.
      const double tr = M(0, 0) + M(1, 1);
      const double disc = std::sqrt(
          std::max(0.0, 0.25 * (M(0, 0) - M(1, 1)) * (M(0, 0) - M(1, 1)) + M(0, 1) * M(0, 1)));
      const double l1 = 0.5 * tr + disc, l2 = 0.5 * tr - disc;
      if (!(l2 > 1e-12)) {
        lost = true;
        break;
      }
      if (l2 / l1 >= params.isotropyRatio) {
        converged = true;
        break;
      }
      // Eigenvector of l1.
      double vx = M(0, 1), vy = l1 - M(0, 0);
      if (std::hypot(vx, vy) < 1e-12) {
        vx = l1 - M(1, 1);
        vy = M(0, 1);
      }
      const double vn = std::hypot(vx, vy);
      vx /= vn;
      vy /= vn;
      // M^{-1/2} = V diag(l1^-1/2, l2^-1/2) V^T; the shape follows it so that the next patch's M
      // is isotropic, then is rescaled to keep the region's area.
      const double i1 = 1 / std::sqrt(l1), i2 = 1 / std::sqrt(l2);
      const cv::Matx22d invSqrt(i1 * vx * vx + i2 * vy * vy, (i1 - i2) * vx * vy,
                                (i1 - i2) * vx * vy, i1 * vy * vy + i2 * vx * vx);
      shape = shape * invSqrt;
      shape *= c.scale / std::sqrt(std::abs(cv::determinant(shape)));
      // Reject regions that degenerate into needles (edges, not corners).
      cv::Matx22d sts = shape.t() * shape;
      const double t2 = sts(0, 0) + sts(1, 1);
      const double d2 = std::sqrt(std::max(
          0.0, 0.25 * (sts(0, 0) - sts(1, 1)) * (sts(0, 0) - sts(1, 1)) + sts(0, 1) * sts(0, 1)));
      const double smax = std::sqrt(0.5 * t2 + d2),
                   smin = std::sqrt(std::max(1e-18, 0.5 * t2 - d2));
      if (smax / smin > params.maxAnisotropy) lost = true;
    }
    if (converged && !lost) out.push_back({c.pt, shape, c.response});
  }
  return out;
}

}  // namespace facet
