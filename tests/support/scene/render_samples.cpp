// render_samples: writes the demo sample images of recipes/samples (and their ground truth as
// <image>.json) with the test-scene generator.
//
//   render_samples [output-dir]     (default: recipes/samples)
#include <filesystem>
#include <iostream>

#include "algorithms/geometry/pose2d.hpp"
#include "tests/support/scene/parts.hpp"
#include "tests/support/scene/scene.hpp"

namespace {

using namespace facet::scene;

// The bracket part at an arbitrary subpixel pose among a little clutter, 8-bit.
void bracket(const std::filesystem::path& dir) {
  SceneSpec spec;
  spec.size = {320, 240};
  spec.background = 50;
  spec.blurSigma = 1.0;
  spec.noiseSigma = 2.0;
  spec.seed = 11;
  Scene scene(spec);
  const facet::Pose2D pose{161.3, 118.7, facet::radians(23.0), 1.0};
  const cv::Rect2d box = placePart(scene, bracketPart(), pose, 170, 50);
  scene.addClutter(4, 12, 30, {box});
  scene.annotations()["pose"] = {{"x", pose.x}, {"y", pose.y}, {"angle_deg", 23.0}, {"scale", 1.0}};
  scene.write(dir / "bracket.png");
}

// Discs of radius 8..40 px, dark on light, 16-bit.
void discs16(const std::filesystem::path& dir) {
  SceneSpec spec;
  spec.size = {256, 192};
  spec.background = 180;
  spec.blurSigma = 1.2;
  spec.noiseSigma = 1.0;
  spec.depth = CV_16U;
  spec.seed = 12;
  Scene scene(spec);
  scene.addDisc({60.4, 60.2}, 40, 70);
  scene.addDisc({170.7, 55.1}, 25, 70);
  scene.addDisc({120.3, 140.6}, 15, 70);
  scene.addDisc({210.2, 145.9}, 8, 70);
  scene.write(dir / "discs_16bit.png");
}

// A rotated hexagon with a soft (sigma 1.5) edge and an illumination gradient, 8-bit.
void hexagon(const std::filesystem::path& dir) {
  SceneSpec spec;
  spec.size = {256, 256};
  spec.background = 40;
  spec.blurSigma = 1.5;
  spec.noiseSigma = 2.0;
  spec.illuminationGradient = {0.15, -0.1};
  spec.seed = 13;
  Scene scene(spec);
  std::vector<cv::Point2d> v;
  for (int i = 0; i < 6; ++i) {
    const double a = facet::radians(17.0 + 60.0 * i);
    v.push_back({128.3 + 90 * std::cos(a), 127.6 + 90 * std::sin(a)});
  }
  scene.addPolygon(v, 150);
  scene.write(dir / "hexagon.png");
}

}  // namespace

int main(int argc, char** argv) {
  const std::filesystem::path dir = argc > 1 ? argv[1] : "recipes/samples";
  std::filesystem::create_directories(dir);
  bracket(dir);
  discs16(dir);
  hexagon(dir);
  std::cout << "wrote bracket.png, discs_16bit.png, hexagon.png to " << dir << "\n";
  return 0;
}
