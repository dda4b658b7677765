#pragma once
// What an inspection draws over the image for people: found contours, measured circles, search
// regions and values, green where a step passed and red where it failed.

#include <string>
#include <vector>

#include <opencv2/core.hpp>

namespace facet::service {

struct OverlayShape {
  enum class Kind { Polyline, Polygon, Circle, Cross, Label };
  Kind kind = Kind::Polyline;
  std::vector<cv::Point2d> points;  // Polyline/Polygon vertices; Circle/Cross/Label: points[0]
  double radius = 0;                // Circle radius / Cross size, pixels
  std::string text;                 // Label
  bool pass = true;                 // colour: green (pass) or red (fail)
  bool secondary = false;           // drawn thin and grey-blue (search regions, nominal positions)
};

struct Overlay {
  std::vector<OverlayShape> shapes;
  void polyline(std::vector<cv::Point2d> pts, bool pass, bool secondary = false);
  void polygon(std::vector<cv::Point2d> pts, bool pass, bool secondary = false);
  void circle(cv::Point2d centre, double radius, bool pass, bool secondary = false);
  void cross(cv::Point2d centre, double size, bool pass);
  void label(cv::Point2d at, std::string text, bool pass);
};

// An 8-bit BGR picture of `image` (Mono8, Mono16 or BGR8) with the overlay and a verdict banner.
cv::Mat drawOverlay(const cv::Mat& image, const Overlay& overlay, const std::string& banner,
                    bool pass);

}  // namespace facet::service
