#include "tests/support/scene/calibration_plates.hpp"

#include <cstdint>
#include <random>
#include <stdexcept>

#include <opencv2/aruco/dictionary.hpp>

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

void addCharucoPlate(PlaneScene& scene, int squaresX, int squaresY, double square, double marker,
                     int dictionary, double dark, double light) {
  if (squaresX < 2 || squaresY < 2 || !(marker > 0 && marker < square))
    throw std::invalid_argument("ChArUco plate: needs 2 x 2 squares and markers inside them");
  const cv::Ptr<cv::aruco::Dictionary> dict = cv::aruco::getPredefinedDictionary(dictionary);
  const int bits = dict->markerSize, cells = bits + 2;
  const int markers = (squaresX * squaresY) / 2;
  if (markers > dict->bytesList.rows)
    throw std::invalid_argument(
        "ChArUco plate: more light squares than the dictionary has markers");
  // In the plate frame (OpenCV's board frame less (square, square)) square (i, j), i across and
  // j down, spans [i - 1, i] x [j - 1, j] squares; dark when i + j is even.
  const double x0 = -2 * square, y0 = -2 * square;
  const double x1 = squaresX * square, y1 = squaresY * square;
  scene.addPolygon(rectangle(x0, y0, x1, y1), light);
  std::vector<std::vector<cv::Point2d>> black;
  const double cell = marker / cells, inset = (square - marker) / 2;
  int id = 0;
  for (int j = 0; j < squaresY; ++j)
    for (int i = 0; i < squaresX; ++i) {
      const double a = (i - 1) * square, b = (j - 1) * square;
      if ((i + j) % 2 == 0) {
        black.push_back(rectangle(a, b, a + square, b + square));
        continue;
      }
      // Bit (r, c) is the cell r down, c across inside the border; a set bit is white.
      const cv::Mat code =
          cv::aruco::Dictionary::getBitsFromByteList(dict->bytesList.rowRange(id, id + 1), bits);
      ++id;
      const double mx = a + inset, my = b + inset;
      for (int r = 0; r < cells; ++r) {
        // Each run of black cells along a row is one rectangle; runs never overlap.
        auto isBlack = [&](int c) {
          return r == 0 || r == cells - 1 || c == 0 || c == cells - 1 ||
                 code.at<std::uint8_t>(r - 1, c - 1) == 0;
        };
        for (int c = 0; c < cells;) {
          if (!isBlack(c)) {
            ++c;
            continue;
          }
          const int start = c;
          while (c < cells && isBlack(c)) ++c;
          black.push_back(
              rectangle(mx + start * cell, my + r * cell, mx + c * cell, my + (r + 1) * cell));
        }
      }
    }
  scene.addPolygons(std::move(black), dark);
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
