// bench_elliptic_rims: round features the image shows as ellipses (a hole or a disc on a plane
// viewed at a tilt, without a plane calibration), measured by the circle measurement with its
// defaults (an elliptic rim measured as its ellipse) beside, in the same run, the same
// measurement with the circle model alone (facet before) and cv::fitEllipseAMS on the Canny
// pixels of the search annulus (what an OpenCV user would write).
//
// Scenes: ellipses of axes ratio 1 (round), 0.97, 0.9, 0.8 (views at about 0, 14, 26, 37
// degrees) with the area of a circle of radius 10, 30, 100 px, at a random angle and subpixel
// centre; blur 1, noise 2, contrast 100, an illumination ramp, clutter blobs near the rim and
// elsewhere (bench_circle's hard case), with and without an occluder hiding 30% of the rim. The
// coarse centre is off by up to 2 px; the annulus's half-width is 5 px plus half the axes'
// difference. Errors: the centre, from the ellipse's exact centre. "refused" = no result.
//
// Usage: bench_elliptic_rims [--smoke] [--scenes N] [--seed N]
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <numbers>
#include <random>
#include <vector>

#include <opencv2/imgproc.hpp>

#include "algorithms/circle/circle_measure.hpp"
#include "bench/circle/annulus_ellipse_baseline.hpp"
#include "bench/scene_run_args.hpp"
#include "tests/support/scene/scene.hpp"

namespace {

constexpr double kPi = std::numbers::pi;

struct Errors {
  double sum2 = 0;
  int n = 0, refused = 0;
  void add(double e) { sum2 += e * e, ++n; }
  [[nodiscard]] double rms() const { return n ? std::sqrt(sum2 / n) : NAN; }
};

struct Scene {
  cv::Mat image;
  cv::Point2d centre;
  facet::CircleMeasureParams params;
};

Scene makeScene(double ratio, double radius, bool occluded, std::mt19937_64& rng, bool hole,
                int subrows) {
  std::uniform_real_distribution<double> u(0, 1);
  const int side = static_cast<int>(2 * radius + 60);
  facet::scene::SceneSpec spec;
  spec.size = {side, side};
  spec.blurSigma = 1.0;
  spec.noiseSigma = 2;
  spec.subrows = subrows;
  spec.seed = rng();
  spec.background = hole ? 170 : 70;
  const double ramp = 2 * kPi * u(rng);
  spec.illuminationGradient = {60.0 / side * std::cos(ramp), 60.0 / side * std::sin(ramp)};
  facet::scene::Scene s(spec);
  Scene out;
  out.centre = {(side - 1) / 2.0 + u(rng) - 0.5, (side - 1) / 2.0 + u(rng) - 0.5};
  const double a = radius / std::sqrt(ratio), b = radius * std::sqrt(ratio), turn = kPi * u(rng);
  std::vector<cv::Point2d> outline;
  for (int i = 0; i < 720; ++i) {
    const double t = 2 * kPi * i / 720, x = a * std::cos(t), y = b * std::sin(t);
    outline.push_back({out.centre.x + x * std::cos(turn) - y * std::sin(turn),
                       out.centre.y + x * std::sin(turn) + y * std::cos(turn)});
  }
  s.addPolygon(outline, hole ? 70 : 170, hole ? "hole" : "object");
  const cv::Rect2d box{out.centre.x - a, out.centre.y - a, 2 * a, 2 * a};
  s.addClutter(6, 4.0, 0.3 * radius + 4.0, {box}, 0.0, 255.0);
  for (int i = 0; i < 3; ++i) {  // blobs 3-4.5 px inside or outside the rim
    const double at = 2 * kPi * u(rng), off = (u(rng) < 0.5 ? -1.0 : 1.0) * (3.0 + 1.5 * u(rng));
    s.addDisc({out.centre.x + (radius + off) * std::cos(at),
               out.centre.y + (radius + off) * std::sin(at)},
              0.7 + (std::abs(off) - 2.2) * u(rng), 255.0 * u(rng), "clutter");
  }
  if (occluded) s.addOccluder(box, 0.206, 100.0 + 60.0 * u(rng));
  out.image = s.render();
  const double ea = 2 * kPi * u(rng), er = 2.0 * std::sqrt(u(rng));
  out.params.centre = {out.centre.x + er * std::cos(ea), out.centre.y + er * std::sin(ea)};
  out.params.radius = radius;
  out.params.width = 5 + (a - b) / 2;
  out.params.polarity =
      hole ? facet::CirclePolarity::DarkToLight : facet::CirclePolarity::LightToDark;
  return out;
}

}  // namespace

int main(int argc, char** argv) {
  const auto args = facet::bench::parseSceneRunArgs(argc, argv, "bench_elliptic_rims", 60, 2);
  if (!args) return 2;
  const auto [smoke, scenes, seed] = *args;
  cv::setNumThreads(1);
  std::printf(
      "bench_elliptic_rims: %d scenes per row (half discs, half holes), blur 1, noise 2, clutter "
      "and a ramp, seed %llu; RMS centre error, px, over the scenes each method measured\n",
      scenes, static_cast<unsigned long long>(seed));
  std::printf(
      "| axes ratio |   r | occluded |  facet | refused | circle model | refused | "
      "fitEllipseAMS | refused | facet / circle | facet / AMS |\n");
  std::printf("|---|---|---|---|---|---|---|---|---|---|---|\n");
  for (const double ratio : {1.0, 0.97, 0.9, 0.8})
    for (const double radius : {10.0, 30.0, 100.0})
      for (const bool occluded : {false, true}) {
        std::mt19937_64 rng(seed * 1000003 + static_cast<std::uint64_t>(ratio * 1000) * 1000 +
                            static_cast<std::uint64_t>(radius) * 2 + (occluded ? 1 : 0));
        Errors facet, circle, ams;
        for (int k = 0; k < scenes; ++k) {
          Scene s = makeScene(ratio, radius, occluded, rng, k % 2 == 1, smoke ? 16 : 64);
          const facet::CircleMeasurement m = facet::measureCircle(s.image, s.params);
          if (m.status.ok())
            facet.add(cv::norm(m.centre - s.centre));
          else
            ++facet.refused;
          s.params.measureEllipticRims = false;
          const facet::CircleMeasurement c = facet::measureCircle(s.image, s.params);
          if (c.status.ok())
            circle.add(cv::norm(c.centre - s.centre));
          else
            ++circle.refused;
          if (const auto e = facet::bench::annulusEllipseAMS(s.image, s.params))
            ams.add(cv::norm(cv::Point2d(e->center) - s.centre));
          else
            ++ams.refused;
        }
        std::printf(
            "| %10.2f | %3.0f | %8s | %6.4f | %7d | %12.4f | %7d | %13.4f | %7d | %14.2f | %11.2f "
            "|\n",
            ratio, radius, occluded ? "yes" : "no", facet.rms(), facet.refused, circle.rms(),
            circle.refused, ams.rms(), ams.refused, facet.rms() / circle.rms(),
            facet.rms() / ams.rms());
      }
  std::printf(
      "facet = the circle measurement's defaults; circle model = the same with "
      "measureEllipticRims off (facet before); fitEllipseAMS = OpenCV's ellipse fit on the "
      "Canny pixels of the annulus\n");
  return 0;
}
