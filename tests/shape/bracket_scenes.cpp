#include "tests/shape/bracket_scenes.hpp"

namespace facet::testing {

scene::SceneSpec bracketSpec(cv::Size size, std::uint64_t seed) {
  scene::SceneSpec spec;
  spec.size = size;
  spec.background = kBackground;
  spec.blurSigma = 0.8;
  spec.noiseSigma = 2.0;
  spec.seed = seed;
  return spec;
}

cv::Mat bracketTemplate(int depth) {
  scene::SceneSpec spec = bracketSpec({}, 99);
  spec.depth = depth;
  return scene::templateScene(scene::bracketPart(), spec, kPartGrey).render();
}

cv::Mat bracketScene(cv::Size size, const std::vector<Pose2D>& poses, std::uint64_t seed,
                     double partGrey, double background, int depth) {
  scene::SceneSpec spec = bracketSpec(size, seed);
  spec.background = background;
  spec.depth = depth;
  scene::Scene s(spec);
  for (const Pose2D& pose : poses)
    scene::placePart(s, scene::bracketPart(), pose, partGrey, background);
  return s.render();
}

}  // namespace facet::testing
