#include "tests/support/scan_room/scan_room.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>

namespace facet::scan_room {
namespace {

constexpr double kNoHit = std::numeric_limits<double>::infinity();

// Distance along the unit ray o + s d to the segment, or +inf.
double hitSegment(const Eigen::Vector2d& o, const Eigen::Vector2d& d, const Segment& w) {
  const Eigen::Vector2d e = w.b - w.a;
  const double denom = d.x() * e.y() - d.y() * e.x();
  if (std::abs(denom) < 1e-12) return kNoHit;
  const Eigen::Vector2d q = w.a - o;
  const double s = (q.x() * e.y() - q.y() * e.x()) / denom;  // along the ray
  const double u = (q.x() * d.y() - q.y() * d.x()) / denom;  // along the segment
  return (s > 1e-9 && u >= 0.0 && u <= 1.0) ? s : kNoHit;
}

double hitDisc(const Eigen::Vector2d& o, const Eigen::Vector2d& d, const Disc& c) {
  const Eigen::Vector2d m = o - c.centre;
  const double b = m.dot(d);
  const double disc = b * b - (m.squaredNorm() - c.radius * c.radius);
  if (disc < 0.0) return kNoHit;
  const double s = -b - std::sqrt(disc);
  return s > 1e-9 ? s : kNoHit;
}

bool insideAnything(const Room& room, const Eigen::Vector2d& p, double clearance) {
  for (const Disc& c : room.occluders)
    if ((p - c.centre).norm() < c.radius + clearance) return true;
  // Distance to walls.
  for (const Segment& w : room.walls) {
    const Eigen::Vector2d e = w.b - w.a;
    const double t = std::clamp((p - w.a).dot(e) / e.squaredNorm(), 0.0, 1.0);
    if ((w.a + t * e - p).norm() < clearance) return true;
  }
  return false;
}

}  // namespace

void Room::addPolygon(const std::vector<Eigen::Vector2d>& corners) {
  for (std::size_t i = 0; i < corners.size(); ++i)
    walls.push_back({corners[i], corners[(i + 1) % corners.size()]});
}

void Room::addBox(const Eigen::Vector2d& centre, double width, double height) {
  const Eigen::Vector2d h(width / 2, height / 2);
  addPolygon({centre + Eigen::Vector2d(-h.x(), -h.y()), centre + Eigen::Vector2d(h.x(), -h.y()),
              centre + Eigen::Vector2d(h.x(), h.y()), centre + Eigen::Vector2d(-h.x(), h.y())});
}

std::vector<double> castRanges(const Room& room, const scan::ScanPose& pose,
                               const ScannerSpec& spec, std::mt19937_64& rng) {
  std::normal_distribution<double> noise(0.0, spec.rangeSigma);
  std::vector<double> ranges(static_cast<std::size_t>(spec.beams), kNoHit);
  const Eigen::Vector2d o(pose.x, pose.y);
  for (int i = 0; i < spec.beams; ++i) {
    const double a = pose.theta + spec.firstAngle + i * spec.angleStep;
    const Eigen::Vector2d d(std::cos(a), std::sin(a));
    double best = kNoHit;
    for (const Segment& w : room.walls) best = std::min(best, hitSegment(o, d, w));
    for (const Disc& c : room.occluders) best = std::min(best, hitDisc(o, d, c));
    if (best < spec.maxRange) ranges[static_cast<std::size_t>(i)] = best + noise(rng);
  }
  return ranges;
}

scan::Scan castScan(const Room& room, const scan::ScanPose& pose, const ScannerSpec& spec,
                    std::mt19937_64& rng) {
  return scan::scanFromRanges(castRanges(room, pose, spec, rng), spec.firstAngle, spec.angleStep,
                              {0.0, spec.maxRange});
}

Room officeRoom() {
  Room room;
  // Hall with an alcove on the upper wall and a recess on the right.
  room.addPolygon({{0, 0},
                   {12, 0},
                   {12, 3},
                   {12.8, 3},
                   {12.8, 5},
                   {12, 5},
                   {12, 8},
                   {7, 8},
                   {7, 9.5},
                   {4, 9.5},
                   {4, 8},
                   {0, 8}});
  room.addBox({3.0, 3.0}, 0.5, 0.5);
  room.addBox({8.5, 5.0}, 0.6, 0.6);
  room.addBox({10.8, 1.0}, 1.6, 0.6);  // cabinet
  return room;
}

OcclusionCase makeOcclusionCase(std::uint64_t seed, double maxShift, double maxTurn, int occluders,
                                const ScannerSpec& spec) {
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  const Room empty = officeRoom();
  const auto freeSpot = [&](const Room& room, double clearance) {
    for (int attempt = 0; attempt < 1000; ++attempt) {
      const Eigen::Vector2d p(1.0 + 10.0 * unit(rng), 1.0 + 6.0 * unit(rng));
      if (!insideAnything(room, p, clearance)) return p;
    }
    return Eigen::Vector2d(6.0, 4.0);
  };
  const Eigen::Vector2d p0 = freeSpot(empty, 0.8);
  const scan::ScanPose refPose{p0.x(), p0.y(), (2.0 * unit(rng) - 1.0) * std::numbers::pi};
  scan::ScanPose newPose;
  for (int attempt = 0; attempt < 1000; ++attempt) {
    const double r = maxShift * std::sqrt(unit(rng)), phi = 2.0 * std::numbers::pi * unit(rng);
    newPose = {refPose.x + r * std::cos(phi), refPose.y + r * std::sin(phi),
               refPose.theta + (2.0 * unit(rng) - 1.0) * maxTurn};
    if (!insideAnything(empty, {newPose.x, newPose.y}, 0.5)) break;
  }
  // People stand within a few metres in front of each scanner, differently in each scan.
  const auto withPeople = [&](const scan::ScanPose& pose) {
    Room room = empty;
    for (int k = 0; k < occluders; ++k) {
      for (int attempt = 0; attempt < 100; ++attempt) {
        const double r = 0.8 + 2.5 * unit(rng);
        const double a = pose.theta + (unit(rng) - 0.5) * std::numbers::pi;
        const Eigen::Vector2d c(pose.x + r * std::cos(a), pose.y + r * std::sin(a));
        const double radius = 0.15 + 0.25 * unit(rng);
        if ((c - Eigen::Vector2d(refPose.x, refPose.y)).norm() < radius + 0.3 ||
            (c - Eigen::Vector2d(newPose.x, newPose.y)).norm() < radius + 0.3 ||
            insideAnything(room, c, radius))
          continue;
        room.occluders.push_back({c, radius});
        break;
      }
    }
    return room;
  };
  OcclusionCase out;
  out.reference = castScan(withPeople(refPose), refPose, spec, rng);
  out.scan = castScan(withPeople(newPose), newPose, spec, rng);
  out.truth = refPose.inverse() * newPose;
  return out;
}

}  // namespace facet::scan_room
