#include "tests/shape/nested_part_scenes.hpp"

#include <vector>

#include <opencv2/imgproc.hpp>

#include "tests/support/scene/scene.hpp"

namespace facet::testing {
namespace {

// Part coordinates, each primitive with its own grey.
std::vector<scene::Primitive> nestedContoursPart() {
  const auto box = [](double x0, double y0, double x1, double y1, double grey) {
    scene::Primitive p;
    p.vertices = {{x0, y0}, {x1, y0}, {x1, y1}, {x0, y1}};
    p.grey = grey;
    return p;
  };
  const auto disc = [](double x, double y, double r, double grey) {
    scene::Primitive p;
    p.kind = scene::Primitive::Kind::Disc;
    p.centre = {x, y};
    p.radius = r;
    p.grey = grey;
    return p;
  };
  return {box(-51.2, -34.9, 51.7, 35.2, 150.0), box(-48.7, -32.6, 48.1, 32.6, 90.0),
          box(-46.4, -29.8, 45.4, 29.8, 190.0), box(-39.1, -25.3, -6.8, -22.4, 240.0),
          disc(-10.9, 1.8, 15.2, 70.0),         disc(-10.1, 1.3, 12.6, 215.0),
          disc(-9.4, 0.7, 10.1, 120.0),         disc(24.2, -0.1, 7.3, 60.0),
          disc(24.4, 0.4, 4.8, 230.0)};
}

}  // namespace

cv::Mat nestedPartScene(cv::Size size, const Pose2D& pose, std::uint64_t seed, bool sharpened,
                        cv::Point2d lensShift) {
  scene::SceneSpec spec;
  spec.size = size;
  spec.background = 40.0;
  spec.blurSigma = 0.9;
  spec.blurModel = scene::BlurModel::Lens;
  spec.noiseSigma = 2.0;
  spec.seed = seed;
  scene::Scene s(spec);
  const std::vector<scene::Primitive> part = nestedContoursPart();
  for (std::size_t i = 0; i < part.size(); ++i) {
    scene::Primitive p = part[i];
    // The housing (the first) stays, the frame's boxes move one way and the lens's discs the other.
    const bool disc = p.kind == scene::Primitive::Kind::Disc;
    const cv::Point2d shift = i == 0 ? cv::Point2d(0.0, 0.0) : disc ? lensShift : -lensShift;
    if (disc)
      p.centre = pose.apply(p.centre + shift);
    else
      for (auto& v : p.vertices) v = pose.apply(v + shift);
    s.add(std::move(p));
  }
  const cv::Mat image = s.render();
  if (!sharpened) return image;
  cv::Mat blurred, out;
  cv::GaussianBlur(image, blurred, {0, 0}, 1.5);
  cv::addWeighted(image, 2.0, blurred, -1.0, 0.0, out);
  return out;
}

}  // namespace facet::testing
