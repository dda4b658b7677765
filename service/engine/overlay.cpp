#include "service/engine/overlay.hpp"

#include <opencv2/imgproc.hpp>

namespace facet::service {
namespace {

const cv::Scalar kPass{60, 200, 60};
const cv::Scalar kFail{40, 40, 230};
const cv::Scalar kSecondary{200, 160, 90};

// Subpixel drawing: OpenCV's shift parameter takes fixed-point coordinates.
constexpr int kShift = 4;
cv::Point fixedPoint(cv::Point2d p) {
  return {cvRound(p.x * (1 << kShift)), cvRound(p.y * (1 << kShift))};
}

}  // namespace

void Overlay::polyline(std::vector<cv::Point2d> pts, bool pass, bool secondary) {
  shapes.push_back({OverlayShape::Kind::Polyline, std::move(pts), 0, "", pass, secondary});
}
void Overlay::polygon(std::vector<cv::Point2d> pts, bool pass, bool secondary) {
  shapes.push_back({OverlayShape::Kind::Polygon, std::move(pts), 0, "", pass, secondary});
}
void Overlay::circle(cv::Point2d centre, double radius, bool pass, bool secondary) {
  shapes.push_back({OverlayShape::Kind::Circle, {centre}, radius, "", pass, secondary});
}
void Overlay::cross(cv::Point2d centre, double size, bool pass) {
  shapes.push_back({OverlayShape::Kind::Cross, {centre}, size, "", pass, false});
}
void Overlay::label(cv::Point2d at, std::string text, bool pass) {
  shapes.push_back({OverlayShape::Kind::Label, {at}, 0, std::move(text), pass, false});
}

cv::Mat drawOverlay(const cv::Mat& image, const Overlay& overlay, const std::string& banner,
                    bool pass) {
  cv::Mat grey8;
  if (image.depth() == CV_16U)
    image.convertTo(grey8, CV_8U, 1.0 / 256.0);
  else
    grey8 = image;
  cv::Mat out;
  if (grey8.channels() == 1)
    cv::cvtColor(grey8, out, cv::COLOR_GRAY2BGR);
  else
    out = grey8.clone();
  const int thick = std::max(1, out.cols / 640);
  for (const auto& s : overlay.shapes) {
    const cv::Scalar colour = s.secondary ? kSecondary : (s.pass ? kPass : kFail);
    const int width = s.secondary ? 1 : thick;
    switch (s.kind) {
      case OverlayShape::Kind::Polyline:
      case OverlayShape::Kind::Polygon: {
        std::vector<cv::Point> pts;
        for (const auto& p : s.points) pts.push_back(fixedPoint(p));
        if (pts.size() >= 2)
          cv::polylines(out, pts, s.kind == OverlayShape::Kind::Polygon, colour, width, cv::LINE_AA,
                        kShift);
        else if (pts.size() == 1)
          cv::circle(out, pts[0], 1 << kShift, colour, cv::FILLED, cv::LINE_AA, kShift);
        break;
      }
      case OverlayShape::Kind::Circle:
        cv::circle(out, fixedPoint(s.points[0]), cvRound(s.radius * (1 << kShift)), colour, width,
                   cv::LINE_AA, kShift);
        break;
      case OverlayShape::Kind::Cross: {
        const auto c = s.points[0];
        cv::line(out, fixedPoint(c - cv::Point2d(s.radius, 0)),
                 fixedPoint(c + cv::Point2d(s.radius, 0)), colour, width, cv::LINE_AA, kShift);
        cv::line(out, fixedPoint(c - cv::Point2d(0, s.radius)),
                 fixedPoint(c + cv::Point2d(0, s.radius)), colour, width, cv::LINE_AA, kShift);
        break;
      }
      case OverlayShape::Kind::Label:
        cv::putText(out, s.text, cv::Point(cvRound(s.points[0].x), cvRound(s.points[0].y)),
                    cv::FONT_HERSHEY_SIMPLEX, 0.4 * thick, colour, 1, cv::LINE_AA);
        break;
    }
  }
  // Verdict banner across the top.
  const int h = 22 * thick;
  cv::rectangle(out, {0, 0, out.cols, h}, pass ? kPass : kFail, cv::FILLED);
  cv::putText(out, banner, {6, h - 7 * thick}, cv::FONT_HERSHEY_SIMPLEX, 0.5 * thick,
              {255, 255, 255}, thick, cv::LINE_AA);
  return out;
}

}  // namespace facet::service
