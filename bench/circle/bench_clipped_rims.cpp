// bench_clipped_rims: holes in a backlight the sensor clips (an overexposed backlight, the
// usual way a line lights a part for measuring), measured by the circle measurement with its
// defaults (the clipped pixels fitted as censored: censored_pixels.hpp) beside, in the same
// run: the same measurement with the clip invisible to it (the image's grey values in a 16-bit
// image, 256 times the 8-bit ones: the 8-bit clip, 255, is no limit of 16 bits, so every pixel is
// fitted as it reads: facet before), its edge points alone (refineWithGreyValues off), and
// cv::fitEllipseAMS on the Canny pixels of the annulus (what an OpenCV user would write; the
// radius is the ellipse's geometric mean).
//
// Scenes: a hole (grey 30) of radius 10, 30, 100 px at a subpixel centre in a background whose
// light is `light` grey levels (230: within the sensor's range; 300, 400, 500, 1000: 1.2 to 3.9
// times the clip at 255), blur 1 px before pixel integration (lens) or on the pixel grid, noise
// 2. "seen" = the share of the step below the clip: under one half the step's middle is not in
// the image, and facet refuses the rim. Errors: RMS over the scenes each method measured, px.
//
// Usage: bench_clipped_rims [--smoke] [--scenes N] [--seed N]
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <random>
#include <vector>

#include <opencv2/imgproc.hpp>

#include "algorithms/circle/circle_measure.hpp"
#include "bench/circle/annulus_ellipse_baseline.hpp"
#include "bench/scene_run_args.hpp"
#include "tests/support/scene/scene.hpp"

namespace {

constexpr double kHoleGrey = 30.0;

struct Errors {
  double centre2 = 0, radius2 = 0, radiusSum = 0;
  int n = 0, refused = 0;
  void add(cv::Point2d centreError, double radiusError) {
    centre2 += centreError.dot(centreError);
    radius2 += radiusError * radiusError;
    radiusSum += radiusError;
    ++n;
  }
  [[nodiscard]] double centreRms() const { return n ? std::sqrt(centre2 / n) : NAN; }
  [[nodiscard]] double radiusRms() const { return n ? std::sqrt(radius2 / n) : NAN; }
  [[nodiscard]] double radiusBias() const { return n ? radiusSum / n : NAN; }
};

struct Scene {
  cv::Mat image;
  cv::Point2d centre;
  double radius = 0;
  facet::CircleMeasureParams params;
};

Scene makeScene(double radius, double light, facet::scene::BlurModel blur, std::mt19937_64& rng,
                int subrows) {
  std::uniform_real_distribution<double> u(0, 1);
  const int side = static_cast<int>(2 * radius + 40);
  facet::scene::SceneSpec spec;
  spec.size = {side, side};
  spec.background = light;
  spec.blurSigma = 1.0;
  spec.blurModel = blur;
  spec.noiseSigma = 2;
  spec.subrows = subrows;
  spec.seed = rng();
  facet::scene::Scene s(spec);
  Scene out;
  out.centre = {(side - 1) / 2.0 + u(rng) - 0.5, (side - 1) / 2.0 + u(rng) - 0.5};
  out.radius = radius * (1.0 + 0.02 * (u(rng) - 0.5));
  s.addDisc(out.centre, out.radius, kHoleGrey, "hole");
  out.image = s.render();
  const double ea = 2 * CV_PI * u(rng), er = 1.0 * std::sqrt(u(rng));
  out.params.centre = {out.centre.x + er * std::cos(ea), out.centre.y + er * std::sin(ea)};
  out.params.radius = radius;
  out.params.width = 5;
  out.params.polarity = facet::CirclePolarity::DarkToLight;
  return out;
}

void measure(const cv::Mat& image, const Scene& s, const facet::CircleMeasureParams& p, Errors& e) {
  const facet::CircleMeasurement m = facet::measureCircle(image, p);
  if (m.status.ok())
    e.add(m.centre - s.centre, m.radius - s.radius);
  else
    ++e.refused;
}

// The OpenCV baseline (annulus_ellipse_baseline.hpp); its radius: the axes' geometric mean.
void canonicalEllipse(const Scene& s, Errors& e) {
  const auto r = facet::bench::annulusEllipseAMS(s.image, s.params);
  if (!r) {
    ++e.refused;
    return;
  }
  e.add(cv::Point2d(r->center) - s.centre,
        std::sqrt(r->size.width * r->size.height) / 2.0 - s.radius);
}

}  // namespace

int main(int argc, char** argv) {
  const auto args = facet::bench::parseSceneRunArgs(argc, argv, "bench_clipped_rims", 40, 2);
  if (!args) return 2;
  const auto [smoke, scenes, seed] = *args;
  cv::setNumThreads(1);
  std::printf(
      "bench_clipped_rims: %d scenes per row, a hole (grey 30) in a backlight of `light` grey "
      "levels, clipped at 255; blur 1, noise 2, seed %llu. RMS errors in px over the scenes each "
      "method measured; bias = mean radius error; refused = no result\n",
      scenes, static_cast<unsigned long long>(seed));
  std::printf(
      "| blur | r | light | seen | facet centre | radius | bias | refused | as read centre | "
      "radius | bias | refused | edge points radius | bias | AMS radius | bias |\n");
  std::printf("|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|\n");
  using facet::scene::BlurModel;
  for (const BlurModel blur : {BlurModel::Lens, BlurModel::PixelGrid})
    for (const double radius : {10.0, 30.0, 100.0})
      for (const double light : {230.0, 300.0, 400.0, 500.0, 1000.0}) {
        std::mt19937_64 rng(seed * 1000003 + static_cast<std::uint64_t>(light) * 1000 +
                            static_cast<std::uint64_t>(radius) * 2 +
                            (blur == BlurModel::Lens ? 1 : 0));
        Errors facet, asRead, edges, ams;
        for (int k = 0; k < scenes; ++k) {
          const Scene s = makeScene(radius, light, blur, rng, smoke ? 16 : 64);
          measure(s.image, s, s.params, facet);
          cv::Mat wide;
          s.image.convertTo(wide, CV_16U, 256.0);
          measure(wide, s, s.params, asRead);
          facet::CircleMeasureParams edgeOnly = s.params;
          edgeOnly.refineWithGreyValues = false;
          measure(s.image, s, edgeOnly, edges);
          canonicalEllipse(s, ams);
        }
        const double seen = std::min(1.0, (255.0 - kHoleGrey) / (light - kHoleGrey));
        std::printf(
            "| %s | %3.0f | %4.0f | %4.2f | %6.4f | %6.4f | %+7.4f | %3d | %6.4f | %6.4f | "
            "%+7.4f | %3d | %6.4f | %+7.4f | %6.4f | %+7.4f |\n",
            blur == BlurModel::Lens ? "lens" : "pixel grid", radius, light, seen, facet.centreRms(),
            facet.radiusRms(), facet.radiusBias(), facet.refused, asRead.centreRms(),
            asRead.radiusRms(), asRead.radiusBias(), asRead.refused, edges.radiusRms(),
            edges.radiusBias(), ams.radiusRms(), ams.radiusBias());
      }
  std::printf(
      "facet = the circle measurement's defaults; as read = the same with the clip invisible "
      "(16-bit copy), the grey fit taking the clipped pixels as they read (facet before); edge "
      "points = its edge points alone; AMS = cv::fitEllipseAMS on the Canny pixels\n");
  return 0;
}
