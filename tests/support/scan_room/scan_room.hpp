#pragma once
// A simulated laser scanner in a polygon room: walls are segments, moving occluders (people,
// carts) are discs. Scans are ray-cast exactly, optionally with Gaussian range noise, so the
// relative pose of two scans is known exactly.

#include <cstdint>
#include <random>
#include <vector>

#include <Eigen/Core>

#include "algorithms/scan/scan.hpp"
#include "algorithms/scan/scan_pose.hpp"

namespace facet::scan_room {

struct Segment {
  Eigen::Vector2d a, b;  // metres, world frame
};

struct Disc {
  Eigen::Vector2d centre;
  double radius = 0.2;  // metres
};

struct Room {
  std::vector<Segment> walls;
  std::vector<Disc> occluders;

  // Adds the closed polygon `corners` as walls.
  void addPolygon(const std::vector<Eigen::Vector2d>& corners);
  // Adds an axis-aligned box (a pillar or a cabinet) as four walls.
  void addBox(const Eigen::Vector2d& centre, double width, double height);
};

struct ScannerSpec {
  int beams = 181;
  double firstAngle = -1.5707963267948966;  // radians (-90 deg)
  double angleStep = 0.017453292519943295;  // radians (1 deg)
  double maxRange = 30.0;                   // metres; longer beams return nothing
  double rangeSigma = 0.01;                 // metres, Gaussian range noise
};

// The ranges a scanner at `pose` (world frame) measures; rays that hit nothing give +inf.
[[nodiscard]] std::vector<double> castRanges(const Room& room, const scan::ScanPose& pose,
                                             const ScannerSpec& spec, std::mt19937_64& rng);

// The scan (points in the sensor frame) a scanner at `pose` sees.
[[nodiscard]] scan::Scan castScan(const Room& room, const scan::ScanPose& pose,
                                  const ScannerSpec& spec, std::mt19937_64& rng);

// The office-like test room: a 12 m x 8 m hall with an alcove, two pillars and a cabinet.
[[nodiscard]] Room officeRoom();

// A random heavy-occlusion case in officeRoom(): the reference scanner somewhere inside, the
// second scanner moved by up to `maxShift` metres and `maxTurn` radians, and each scan with its
// own `occluders` discs (people who moved between the scans) placed near the scanners.
struct OcclusionCase {
  scan::Scan reference;
  scan::Scan scan;
  scan::ScanPose truth;  // maps `scan` into `reference`'s frame
};
[[nodiscard]] OcclusionCase makeOcclusionCase(std::uint64_t seed, double maxShift, double maxTurn,
                                              int occluders, const ScannerSpec& spec = {});

}  // namespace facet::scan_room
