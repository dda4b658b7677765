#include "tests/support/scene/parts.hpp"

#include <algorithm>

namespace facet::scene {

PartDrawing bracketPart() {
  PartDrawing part;
  Primitive plate;
  plate.kind = Primitive::Kind::Polygon;
  plate.vertices = {{-65, -50}, {45, -50}, {65, -30}, {65, -5}, {-8, -5}, {-8, 50}, {-65, 50}};
  part.primitives.push_back(plate);
  auto hole = [](cv::Point2d c, double r) {
    Primitive p;
    p.kind = Primitive::Kind::Disc;
    p.centre = c;
    p.radius = r;
    p.role = "hole";
    return p;
  };
  part.primitives.push_back(hole({-42, -28}, 10));
  part.primitives.push_back(hole({38, -27}, 7));
  part.primitives.push_back(hole({-37, 30}, 6));
  part.templateSize = {160, 130};
  return part;
}

cv::Rect2d placePart(Scene& scene, const PartDrawing& part, const Pose2D& pose, double partGrey,
                     double holeGrey) {
  double x0 = 1e300, y0 = 1e300, x1 = -1e300, y1 = -1e300;
  auto grow = [&](cv::Point2d q, double r) {
    x0 = std::min(x0, q.x - r), y0 = std::min(y0, q.y - r);
    x1 = std::max(x1, q.x + r), y1 = std::max(y1, q.y + r);
  };
  for (Primitive p : part.primitives) {
    const bool isHole = p.role == "hole";
    p.grey = isHole ? holeGrey : partGrey;
    if (p.kind == Primitive::Kind::Disc) {
      p.centre = pose.apply(p.centre);
      p.radius *= pose.scale;
      grow(p.centre, p.radius);
    } else {
      for (auto& v : p.vertices) {
        v = pose.apply(v);
        grow(v, 0.0);
      }
    }
    scene.add(std::move(p));
  }
  return {x0, y0, x1 - x0, y1 - y0};
}

Scene templateScene(const PartDrawing& part, SceneSpec spec, double partGrey) {
  spec.size = part.templateSize;
  Scene scene(spec);
  const Pose2D atReference{(spec.size.width - 1) / 2.0, (spec.size.height - 1) / 2.0, 0.0, 1.0};
  placePart(scene, part, atReference, partGrey, spec.background);
  return scene;
}

}  // namespace facet::scene
