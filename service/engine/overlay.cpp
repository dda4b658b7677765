#include "service/engine/overlay.hpp"

#include <algorithm>
#include <sstream>

#include <opencv2/imgproc.hpp>

#include "service/engine/label_placement.hpp"

namespace facet::service {
namespace {

const cv::Scalar kPass{60, 200, 60};
const cv::Scalar kFail{40, 40, 230};
const cv::Scalar kSecondary{200, 160, 90};
// Behind label text, so that it reads on any part; a hue a grey camera image never has.
const cv::Scalar kLabelBacking{70, 30, 20};
constexpr int kFont = cv::FONT_HERSHEY_SIMPLEX;

// `text` broken at spaces into lines no wider than `maxWidth` pixels (a single word may be wider).
std::vector<std::string> wrap(const std::string& text, double scale, int maxWidth) {
  std::vector<std::string> lines;
  std::string line, word;
  int unused = 0;
  auto flush = [&] {
    if (!line.empty()) lines.push_back(line);
    line.clear();
  };
  std::istringstream words(text);
  while (words >> word) {
    const std::string longer = line.empty() ? word : line + " " + word;
    if (!line.empty() && cv::getTextSize(longer, kFont, scale, 1, &unused).width > maxWidth)
      flush(), line = word;
    else
      line = longer;
  }
  flush();
  return lines;
}

// The largest font scale up to `scale` at which `text` is at most `width` pixels wide.
double fittingScale(const std::string& text, double scale, int thickness, int width) {
  int unused = 0;
  const int natural = cv::getTextSize(text, kFont, scale, thickness, &unused).width;
  return natural <= width ? scale : std::max(0.2, scale * width / natural);
}

struct LabelText {
  std::vector<std::string> lines;
  cv::Scalar colour;
  cv::Point2d anchor;
};

// Labels in boxes that stay inside the picture and clear of each other (label_placement.hpp),
// with a thin line back to the point when the box had to move away from it.
void drawLabels(cv::Mat& out, const std::vector<LabelText>& labels, double scale, int top) {
  int baseline = 0;
  const int lineHeight = cv::getTextSize("Ag", kFont, scale, 1, &baseline).height + baseline + 2;
  const int pad = 3;
  std::vector<LabelRequest> requests;
  for (const auto& label : labels) {
    int width = 0;
    for (const auto& line : label.lines)
      width = std::max(width, cv::getTextSize(line, kFont, scale, 1, &baseline).width);
    requests.push_back(
        {label.anchor,
         {width + 2 * pad, static_cast<int>(label.lines.size()) * lineHeight + 2 * pad}});
  }
  const std::vector<cv::Rect> boxes = placeLabels(out.size(), top, requests);
  for (std::size_t i = 0; i < labels.size(); ++i) {
    const cv::Rect& box = boxes[i];
    const cv::Point anchor(cvRound(labels[i].anchor.x), cvRound(labels[i].anchor.y));
    const cv::Point nearest(std::clamp(anchor.x, box.x, box.x + box.width - 1),
                            std::clamp(anchor.y, box.y, box.y + box.height - 1));
    if (cv::norm(nearest - anchor) > 12)
      cv::line(out, anchor, nearest, labels[i].colour, 1, cv::LINE_AA);
    cv::rectangle(out, box, kLabelBacking, cv::FILLED);
    for (std::size_t k = 0; k < labels[i].lines.size(); ++k)
      cv::putText(out, labels[i].lines[k],
                  {box.x + pad, box.y + pad + static_cast<int>(k + 1) * lineHeight - baseline - 2},
                  kFont, scale, labels[i].colour, 1, cv::LINE_AA);
  }
}

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
  const double labelScale = 0.4 * thick;
  std::vector<LabelText> labels;  // drawn last, above every shape
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
        labels.push_back(
            {wrap(s.text, labelScale, std::max(80, out.cols * 2 / 5)), colour, s.points[0]});
        break;
    }
  }
  // Verdict banner across the top; its text shrinks to fit the width.
  const int h = 22 * thick;
  drawLabels(out, labels, labelScale, h);
  cv::rectangle(out, {0, 0, out.cols, h}, pass ? kPass : kFail, cv::FILLED);
  const double bannerScale = fittingScale(banner, 0.5 * thick, thick, out.cols - 12);
  cv::putText(out, banner, {6, h - 7 * thick}, kFont, bannerScale, {255, 255, 255}, thick,
              cv::LINE_AA);
  return out;
}

}  // namespace facet::service
