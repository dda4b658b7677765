#pragma once
// Plane scenes: flat things (calibration plates, parts with holes) seen through a pinhole camera
// with lens distortion, rendered with exact ground truth.
//
// Every outline is given in the plane (mm), subdivided finely (segments of at most 0.2 px in the
// image) and each vertex projected through the camera (rotation, translation, OpenCV's pinhole
// + k1 k2 p1 p2 k3 distortion), so straight edges come out curved as the lens bends them and
// circles come out as the perspective (and distortion) makes them. The pixel value is the exact
// area average of the painted plane over the pixel's square (exact along x, 256 sub-scanlines per
// pixel along y: the midpoint rule is exact between the outline's kinks, leaving < 1e-5 of a
// grey level per pixel; plane_scene_test.cpp checks areas against the polygon formula).
// Shapes are painted in order, each over what lies beneath in proportion to its coverage of the
// pixel; that is exact for one shape over another, but two shapes of one grey that touch would
// each only partly paint their shared pixels, so touching polygons go into one shape
// (addPolygons), whose coverage is their sum.
//
// Lens blur happens before the pixel integrates: with `lensBlurSigma` the coverage is rendered
// on a grid `fineFactor` times finer, blurred there with a Gaussian of that sigma, and then
// averaged over each pixel's square. Noise is added last, then 8-bit quantisation.
//
// The camera's distortion code is written here independently of algorithms/calibration, so a
// mistake in the code under test cannot hide in the ground truth.

#include <cstdint>
#include <vector>

#include <opencv2/core.hpp>

namespace facet::scene {

struct LensCamera {
  cv::Size size{1280, 1024};
  double fx = 1600, fy = 1600, cx = 639.5, cy = 511.5;
  double k1 = 0, k2 = 0, p1 = 0, p2 = 0, k3 = 0;

  // Camera-frame point (mm; z along the optical axis) -> pixel.
  [[nodiscard]] cv::Point2d project(const cv::Vec3d& point) const;
  [[nodiscard]] cv::Point2d distortNormalised(cv::Point2d n) const;
  [[nodiscard]] cv::Matx33d matrix() const { return {fx, 0, cx, 0, fy, cy, 0, 0, 1}; }
  [[nodiscard]] cv::Mat distortion() const;  // 1x5 CV_64F: k1 k2 p1 p2 k3
};

// Pose of the plane (x, y in mm, z into the plane) in the camera frame.
struct PlanePlacement {
  cv::Matx33d rotation = cv::Matx33d::eye();
  cv::Vec3d translationMm{0, 0, 500};
  [[nodiscard]] cv::Vec3d toCamera(cv::Point2d planeMm, double z = 0) const;
};

// The plane point `target` seen from `distanceMm` along a view direction tilted by `tiltDeg`
// about an axis in the plane at `tiltAxisDeg`, the plane spun by `spinDeg` about its normal;
// `target` projects to the image centre shifted by `shiftPx`-ish (applied as a ray offset).
PlanePlacement lookAtPlane(cv::Point2d target, double distanceMm, double tiltDeg,
                           double tiltAxisDeg, double spinDeg, const LensCamera& camera,
                           cv::Point2d shiftPx = {0, 0});

struct PlaneShape {
  std::vector<cv::Point2d> polygon;  // mm, either orientation; empty for a disc
  // Further polygons of the same grey, disjoint from `polygon` and from one another. The shape's
  // coverage is the sum of its polygons' coverages, painted once: exact where they touch (two
  // chessboard squares at a corner, two marker cells along an edge), where painting them one
  // after another would leave the shared pixels partly unpainted.
  std::vector<std::vector<cv::Point2d>> morePolygons;
  cv::Point2d centre;  // disc centre, mm
  double radius = 0;   // disc radius, mm
  double grey = 0;     // 8-bit scale
};

struct PlaneScene {
  LensCamera camera;
  PlanePlacement placement;
  double background = 70;          // beyond every shape
  std::vector<PlaneShape> shapes;  // painted in order
  double lensBlurSigma = 0;        // Gaussian lens blur before pixel integration, pixels
  int fineFactor = 3;              // grid refinement for the lens blur
  double noiseSigma = 0;           // additive Gaussian noise, grey levels
  std::uint64_t seed = 1;

  void addPolygon(std::vector<cv::Point2d> mm, double grey);
  // One shape of several disjoint polygons (mm) of one grey; none may be empty.
  void addPolygons(std::vector<std::vector<cv::Point2d>> mm, double grey);
  void addDisc(cv::Point2d centreMm, double radiusMm, double grey);
  [[nodiscard]] cv::Point2d imageOf(cv::Point2d planeMm) const;  // exact ground truth, pixels
  [[nodiscard]] cv::Mat renderIdeal() const;  // CV_64F, blurred, no noise, not quantised
  [[nodiscard]] cv::Mat render() const;       // CV_8U
};

// The projected, subdivided outline of a shape's first polygon (or its disc), in pixels (exposed
// for the area test).
std::vector<cv::Point2d> projectOutline(const PlaneScene& scene, const PlaneShape& shape,
                                        double scale = 1.0);
// The projected, subdivided outline of a plane polygon (mm), in pixels.
std::vector<cv::Point2d> projectPolygon(const PlaneScene& scene,
                                        const std::vector<cv::Point2d>& polygonMm,
                                        double scale = 1.0);
// Exact-in-x, sub-scanline-in-y coverage of a pixel polygon on a grid of `size` cells.
cv::Mat polygonCoverage(const std::vector<cv::Point2d>& polygon, cv::Size size, int subrows = 256);

}  // namespace facet::scene
