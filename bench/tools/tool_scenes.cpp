#include "bench/tools/tool_scenes.hpp"

#include <cmath>
#include <random>

#include "bench/tools/lens_scene.hpp"
#include "tests/support/scene/scene.hpp"

namespace facet::bench {
namespace {

constexpr double kDeg = CV_PI / 180.0;

cv::Mat render(const scene::Scene& s, BlurModel model, int factor) {
  return model == BlurModel::Lens ? renderLensBlurred(s, factor) : s.render();
}

scene::SceneSpec spec(cv::Size size, double background, SceneNoise n, std::uint64_t seed) {
  scene::SceneSpec sp;
  sp.size = size;
  sp.background = background;
  sp.blurSigma = n.blur;
  sp.noiseSigma = n.noise;
  sp.subrows = 64;
  sp.seed = seed * 7919 + 13;
  return sp;
}

// A half-plane: the side of the line through `p` with unit normal `nrm` where (q - p).nrm > 0,
// as a polygon far larger than the image.
std::vector<cv::Point2d> halfPlane(cv::Point2d p, cv::Point2d nrm) {
  const cv::Point2d t(-nrm.y, nrm.x);
  const double far = 4000;
  return {p + far * t, p + far * t + far * nrm, p - far * t + far * nrm, p - far * t};
}

cv::Point2d axisOf(double deg) {
  return {std::cos(deg * kDeg), -std::sin(deg * kDeg)};
}

// The draws every caliper scene starts with, in this order (each seed's scene depends on it): the
// two greys, then the caliper's place and angle.
struct CaliperStart {
  std::mt19937_64 rng;
  double dark, light;
  MeasuringRect rect;
};
CaliperStart startCaliperScene(std::uint64_t seed, double length) {
  CaliperStart c{std::mt19937_64(seed), 0, 0, {}};
  std::uniform_real_distribution<double> u(0, 1);
  c.dark = 30 + 40 * u(c.rng), c.light = 140 + 60 * u(c.rng);
  c.rect = {31.5 + u(c.rng), 31.5 + u(c.rng), length, 20, 360 * u(c.rng)};
  return c;
}

}  // namespace

const char* blurModelName(BlurModel model) {
  return model == BlurModel::Lens ? "lens" : "pixel grid";
}

EdgeScene makeEdgeScene(std::uint64_t seed, BlurModel model, SceneNoise n) {
  auto [rng, dark, light, rect] = startCaliperScene(seed, 40);
  std::uniform_real_distribution<double> u(0, 1);
  EdgeScene es;
  es.rect = rect;
  es.rising = u(rng) < 0.5;
  es.contrast = light - dark;
  // The edge crosses the axis at `position`, its normal tilted up to 5 degrees off the axis.
  es.position = -6 + 12 * u(rng);
  const cv::Point2d d = axisOf(es.rect.angle);
  const cv::Point2d nrm = axisOf(es.rect.angle + (-5 + 10 * u(rng)));
  const cv::Point2d p = cv::Point2d(es.rect.cx, es.rect.cy) + es.position * d;
  scene::Scene s(spec({64, 64}, es.rising ? dark : light, n, seed));
  // Rising: light beyond the edge along the axis.
  s.addPolygon(halfPlane(p, nrm.dot(d) > 0 ? nrm : -nrm), es.rising ? light : dark);
  es.image = render(s, model, 6);
  return es;
}

BarScene makeBarScene(std::uint64_t seed, double barWidth, BlurModel model, SceneNoise n) {
  auto [rng, dark, light, rect] = startCaliperScene(seed, 40);
  std::uniform_real_distribution<double> u(0, 1);
  BarScene bs;
  bs.rect = rect;
  bs.light = u(rng) < 0.5;
  const double w = barWidth + u(rng);  // subpixel width
  bs.centre = -4 + 8 * u(rng);
  const double tilt = (-5 + 10 * u(rng)) * kDeg;
  const cv::Point2d d = axisOf(bs.rect.angle), nrm = axisOf(bs.rect.angle + tilt / kDeg);
  const cv::Point2d mid = cv::Point2d(bs.rect.cx, bs.rect.cy) + bs.centre * d;
  const cv::Point2d t(-nrm.y, nrm.x);
  const double far = 200, h = w / 2;
  scene::Scene s(spec({64, 64}, bs.light ? dark : light, n, seed));
  s.addPolygon({mid - h * nrm - far * t, mid + h * nrm - far * t, mid + h * nrm + far * t,
                mid - h * nrm + far * t},
               bs.light ? light : dark);
  // Along the axis the bar's edges lie h / cos(tilt) either side of the middle.
  bs.width = w / std::cos(tilt);
  bs.image = render(s, model, 6);
  return bs;
}

CombScene makeCombScene(std::uint64_t seed, int teeth, double barWidth, double gapWidth,
                        BlurModel model, SceneNoise n) {
  auto [rng, dark, light, rect] = startCaliperScene(seed, 48);
  std::uniform_real_distribution<double> u(0, 1);
  CombScene cs;
  cs.rect = rect;
  cs.light = u(rng) < 0.5;
  const double tilt = (-5 + 10 * u(rng)) * kDeg;
  const cv::Point2d nrm = axisOf(cs.rect.angle + tilt / kDeg), t(-nrm.y, nrm.x);
  std::vector<double> w(teeth), gap(teeth - 1);
  double span = 0;
  for (int k = 0; k < teeth; ++k) span += w[k] = barWidth + u(rng);
  for (int k = 0; k + 1 < teeth; ++k) span += gap[k] = gapWidth + u(rng);
  // Along the normal from the comb's start; along the axis distances grow by 1 / cos(tilt).
  double at = -span / 2 + (-3 + 6 * u(rng));
  scene::Scene s(spec({64, 64}, cs.light ? dark : light, n, seed));
  const cv::Point2d origin(cs.rect.cx, cs.rect.cy);
  const double far = 200;
  for (int k = 0; k < teeth; ++k) {
    const cv::Point2d a = origin + at * nrm, b = origin + (at + w[k]) * nrm;
    s.addPolygon({a - far * t, b - far * t, b + far * t, a + far * t}, cs.light ? light : dark);
    cs.widths.push_back(w[k] / std::cos(tilt));
    cs.centres.push_back((at + w[k] / 2) / std::cos(tilt));
    if (k + 1 < teeth) at += w[k] + gap[k];
  }
  cs.image = render(s, model, 6);
  return cs;
}

LineScene makeLineScene(std::uint64_t seed, BlurModel model, SceneNoise n) {
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> u(0, 1);
  const double dark = 30 + 40 * u(rng), light = 140 + 60 * u(rng);
  LineScene ls;
  ls.angleDeg = -180 + 360 * u(rng);
  ls.direction = axisOf(ls.angleDeg);
  ls.point = {124.5 + u(rng), 124.5 + u(rng)};
  // The rectangle is laid roughly along the line: off by up to 1 degree and 3 px across.
  const double rectAngle = ls.angleDeg - 1 + 2 * u(rng);
  const cv::Point2d across(std::sin(rectAngle * kDeg), std::cos(rectAngle * kDeg));
  const cv::Point2d c = ls.point + (-3 + 6 * u(rng)) * across;
  ls.rect = {c.x, c.y, 200, 16, rectAngle};
  scene::Scene s(spec({250, 250}, dark, n, seed));
  const cv::Point2d nrm(-ls.direction.y, ls.direction.x);
  s.addPolygon(halfPlane(ls.point, nrm), light);
  ls.image = render(s, model, 6);
  return ls;
}

BlobScene makeBlobScene(std::uint64_t seed, BlurModel model, SceneNoise n, cv::Size size,
                        int discs) {
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> u(0, 1);
  const double dark = 30 + 40 * u(rng), light = 140 + 60 * u(rng);
  scene::Scene s(spec(size, dark, n, seed));
  BlobScene bs;
  for (int tries = 0; static_cast<int>(bs.radii.size()) < discs && tries < 10000; ++tries) {
    const double r = 6 + 24 * u(rng);
    const cv::Point2d c(r + 10 + (size.width - 2 * r - 20) * u(rng),
                        r + 10 + (size.height - 2 * r - 20) * u(rng));
    bool clear = true;
    for (std::size_t k = 0; k < bs.radii.size() && clear; ++k)
      clear = cv::norm(c - bs.centres[k]) > r + bs.radii[k] + 12;
    if (!clear) continue;
    bs.centres.push_back(c);
    bs.radii.push_back(r);
    s.addDisc(c, r, light);
  }
  bs.image = render(s, model, 4);
  return bs;
}

}  // namespace facet::bench
