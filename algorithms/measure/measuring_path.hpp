#pragma once
// Where a caliper measures: a rotated rectangle or an arc, as a map from (s, t) -- s along the
// measuring axis, t across it -- to image points.
//
// Rectangle (the design's convention): centre (cx, cy), `length` along the axis, `width` across
// it, `angle` in degrees counter-clockwise on screen, axis direction (cos a, -sin a). s runs from
// -length/2 to +length/2 (signed distance from the centre); t from -width/2 to +width/2 along
// (sin a, cos a), the axis turned 90 degrees clockwise on screen.
//
// Arc: centre (cx, cy), `radius`, the arc from `startAngle` over `extent` degrees
// (counter-clockwise on screen for positive extent), `width` radially. s is the arc length at the
// radius, signed from the arc's middle, growing counter-clockwise; t is the radial offset (outwards
// positive). Edges an arc caliper finds are radial lines crossing the arc (teeth, slots around a
// hub).

#include <opencv2/core.hpp>

namespace facet {

struct MeasuringRect {
  double cx = 0, cy = 0;
  double length = 0;  // pixels, along the axis
  double width = 0;   // pixels, across
  double angle = 0;   // degrees, counter-clockwise on screen
};

struct MeasuringArc {
  double cx = 0, cy = 0;
  double radius = 0;      // pixels
  double startAngle = 0;  // degrees, counter-clockwise on screen from the +x axis
  double extent = 0;      // degrees; negative runs clockwise
  double width = 0;       // pixels, radially
};

class MeasuringPath {
 public:
  explicit MeasuringPath(const MeasuringRect& rect);
  explicit MeasuringPath(const MeasuringArc& arc);

  [[nodiscard]] bool isArc() const { return arc_; }
  [[nodiscard]] double length() const { return length_; }
  [[nodiscard]] double width() const { return width_; }
  // The image point at axis position s and cross offset t. (A rectangle's is inline: profile
  // sampling asks for it at every position.)
  [[nodiscard]] cv::Point2d at(double s, double t) const {
    if (!arc_) return {centre_.x + s * cos_ + t * sin_, centre_.y - s * sin_ + t * cos_};
    return arcAt(s, t);
  }
  // The unit measuring direction at s (the tangent for an arc).
  [[nodiscard]] cv::Point2d axisAt(double s) const;
  // The unit direction of growing t at s: at(s, t) = at(s, 0) + t * acrossAt(s).
  [[nodiscard]] cv::Point2d acrossAt(double s) const {
    if (!arc_) return {sin_, cos_};
    return arcAcrossAt(s);
  }
  // Axis-aligned bounds of the path's area in image pixels (not clipped).
  [[nodiscard]] cv::Rect2d bounds() const;

 private:
  [[nodiscard]] cv::Point2d arcAt(double s, double t) const;
  [[nodiscard]] cv::Point2d arcAcrossAt(double s) const;

  bool arc_ = false;
  cv::Point2d centre_;
  double length_ = 0, width_ = 0;
  double angle_ = 0;          // rectangle: axis angle, radians; arc: middle angle, radians
  double radius_ = 0;         // arc only
  double sign_ = 1;           // arc: +1 counter-clockwise, -1 clockwise
  double cos_ = 1, sin_ = 0;  // rectangle: of angle_ (sampling calls at() thousands of times)
};

}  // namespace facet
