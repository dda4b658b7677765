#include "tests/support/scene/calibration_plates.hpp"

#include <random>

namespace facet::scene {
namespace {

std::vector<cv::Point2d> rectangle(double x0, double y0, double x1, double y1) {
  return {{x0, y0}, {x1, y0}, {x1, y1}, {x0, y1}};
}

}  // namespace

void addChessboardPlate(PlaneScene& scene, int cols, int rows, double pitch, double dark,
                        double light) {
  // Squares i = 0..cols, j = 0..rows span [(i-1) p, i p] x [(j-1) p, j p]; dark when i + j is even.
  // The dark squares meet at the inner corners, so they are one shape: exact at the corners.
  const double x0 = -2 * pitch, y0 = -2 * pitch, x1 = (cols + 1) * pitch, y1 = (rows + 1) * pitch;
  scene.addPolygon(rectangle(x0, y0, x1, y1), light);
  std::vector<std::vector<cv::Point2d>> squares;
  for (int j = 0; j <= rows; ++j)
    for (int i = 0; i <= cols; ++i)
      if ((i + j) % 2 == 0)
        squares.push_back(rectangle((i - 1) * pitch, (j - 1) * pitch, i * pitch, j * pitch));
  scene.addPolygons(std::move(squares), dark);
}

void addCirclePlate(PlaneScene& scene, int cols, int rows, double pitch, double diameter,
                    double dark, double light) {
  scene.addPolygon(rectangle(-pitch, -pitch, cols * pitch, rows * pitch), light);
  for (int j = 0; j < rows; ++j)
    for (int i = 0; i < cols; ++i) scene.addDisc({i * pitch, j * pitch}, diameter / 2, dark);
}

std::vector<cv::Point2d> patternImagePoints(const PlaneScene& scene, int cols, int rows,
                                            double pitch) {
  std::vector<cv::Point2d> out;
  for (int j = 0; j < rows; ++j)
    for (int i = 0; i < cols; ++i) out.push_back(scene.imageOf({i * pitch, j * pitch}));
  return out;
}

}  // namespace facet::scene

namespace facet::scene {

PlanePlacement seriesPlacement(const LensCamera& camera, cv::Size2d patternMm, double marginMm,
                               std::uint64_t seed, int index, double maxTiltDeg) {
  std::mt19937_64 rng(seed * 1000003 + static_cast<std::uint64_t>(index));
  std::uniform_real_distribution<double> u(0, 1);
  const cv::Point2d centre(patternMm.width / 2, patternMm.height / 2);
  const double w = camera.size.width, h = camera.size.height;
  PlanePlacement best;
  for (int attempt = 0; attempt < 500; ++attempt) {
    const double fill = 0.45 + 0.3 * u(rng);
    const double distance = (patternMm.width + 2 * marginMm) * camera.fx / (fill * w);
    const double tilt = maxTiltDeg * std::sqrt(u(rng));
    const cv::Point2d shift((u(rng) - 0.5) * w * (1 - fill), (u(rng) - 0.5) * h * (1 - fill));
    PlanePlacement p =
        lookAtPlane(centre, distance, tilt, 360 * u(rng), 50 * (u(rng) - 0.5), camera, shift);
    bool inside = true;
    for (double fx : {0.0, 0.25, 0.5, 0.75, 1.0})
      for (double fy : {0.0, 0.25, 0.5, 0.75, 1.0}) {
        if (fx != 0 && fx != 1 && fy != 0 && fy != 1) continue;
        const cv::Vec3d c = p.toCamera({-marginMm + fx * (patternMm.width + 2 * marginMm),
                                        -marginMm + fy * (patternMm.height + 2 * marginMm)});
        if (c[2] <= 0) {
          inside = false;
          continue;
        }
        const cv::Point2d q = camera.project(c);
        inside = inside && q.x > 4 && q.y > 4 && q.x < w - 5 && q.y < h - 5;
      }
    best = p;
    if (inside) break;
  }
  return best;
}

}  // namespace facet::scene
