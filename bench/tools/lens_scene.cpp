#include "bench/tools/lens_scene.hpp"

#include <algorithm>
#include <cmath>
#include <random>

#include <opencv2/imgproc.hpp>

namespace facet::bench {

cv::Mat renderLensBlurred(const scene::Scene& s, int factor) {
  const scene::SceneSpec& spec = s.spec();
  const int tile = 128;
  const int margin = static_cast<int>(std::ceil(4.0 * spec.blurSigma)) + 2;
  cv::Mat out(spec.size, CV_64F, cv::Scalar(spec.background));
  for (int ty = 0; ty < spec.size.height; ty += tile) {
    for (int tx = 0; tx < spec.size.width; tx += tile) {
      const cv::Rect inner(tx, ty, std::min(tile, spec.size.width - tx),
                           std::min(tile, spec.size.height - ty));
      const cv::Rect outer(inner.x - margin, inner.y - margin, inner.width + 2 * margin,
                           inner.height + 2 * margin);
      scene::SceneSpec fine = spec;
      fine.size = {outer.width * factor, outer.height * factor};
      fine.subrows = 4;
      scene::Scene fs(fine);
      // Coarse pixel (i, j) covers [i - 0.5, i + 0.5]; fine pixel k of it has its centre at
      // i - 0.5 + (k + 0.5) / factor, so a coarse point p maps to (p - outer.tl + 0.5) f - 0.5.
      auto map = [&](cv::Point2d p) {
        return cv::Point2d((p.x - outer.x + 0.5) * factor - 0.5,
                           (p.y - outer.y + 0.5) * factor - 0.5);
      };
      const cv::Rect2d fineBox(outer.x - 1.0, outer.y - 1.0, outer.width + 2.0, outer.height + 2.0);
      bool any = false;
      for (scene::Primitive p : s.primitives()) {
        if (p.kind == scene::Primitive::Kind::Disc) {
          const cv::Rect2d box(p.centre.x - p.radius, p.centre.y - p.radius, 2 * p.radius,
                               2 * p.radius);
          if ((box & fineBox).area() <= 0) continue;
          p.centre = map(p.centre);
          p.radius *= factor;
        } else {
          for (auto& v : p.vertices) v = map(v);
        }
        fs.add(p);
        any = true;
      }
      if (!any) continue;
      cv::Mat ideal = fs.renderIdeal();
      if (spec.blurSigma > 0) {
        const double sf = spec.blurSigma * factor;
        const int k = 2 * static_cast<int>(std::ceil(4.0 * sf)) + 1;
        cv::GaussianBlur(ideal, ideal, cv::Size(k, k), sf, sf, cv::BORDER_REPLICATE);
      }
      cv::Mat coarse;
      cv::resize(ideal, coarse, outer.size(), 0, 0, cv::INTER_AREA);
      coarse(cv::Rect(margin, margin, inner.width, inner.height)).copyTo(out(inner));
    }
  }
  if (spec.noiseSigma > 0) {
    std::mt19937_64 rng(spec.seed);
    std::normal_distribution<double> n(0.0, spec.noiseSigma);
    for (int r = 0; r < out.rows; ++r) {
      auto* row = out.ptr<double>(r);
      for (int c = 0; c < out.cols; ++c) row[c] += n(rng);
    }
  }
  cv::Mat image;
  out.convertTo(image, CV_8U);  // rounds and saturates
  return image;
}

}  // namespace facet::bench
