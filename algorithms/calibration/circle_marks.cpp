#include "algorithms/calibration/circle_marks.hpp"

#include <algorithm>
#include <cmath>
#include <string>

#include <opencv2/calib3d.hpp>
#include <opencv2/core/utility.hpp>
#include <opencv2/features2d.hpp>
#include <opencv2/imgproc.hpp>

#include "algorithms/calibration/conic.hpp"
#include "algorithms/edges/subpixel_edges.hpp"
#include "algorithms/image/grey8.hpp"

namespace facet {
namespace {

// Plate order: right-handed as the camera sees it; of the two 180-degree turns of a symmetric
// grid the one whose first mark is nearer the image's top-left corner.
void toPlateOrder(int cols, int rows, std::vector<cv::Point2d>& p) {
  auto at = [&](int c, int r) -> cv::Point2d& { return p[static_cast<std::size_t>(r * cols + c)]; };
  const cv::Point2d ex = at(1, 0) - at(0, 0), ey = at(0, 1) - at(0, 0);
  if (ex.cross(ey) < 0)
    for (int r = 0; r < rows; ++r) std::reverse(&at(0, r), &at(0, r) + cols);
  if (p.front().x + p.front().y > p.back().x + p.back().y) std::reverse(p.begin(), p.end());
}

// Fits the rim's conic, dropping points more than 3 RMS (at least 0.15 px) off once.
std::optional<cv::Matx33d> robustConic(std::vector<cv::Point2d> pts) {
  auto conic = fitEllipseConic(pts);
  if (!conic) return conic;
  double sum = 0;
  for (const auto& p : pts) sum += std::pow(conicDistance(*conic, p), 2);
  const double limit = std::max(3 * std::sqrt(sum / static_cast<double>(pts.size())), 0.15);
  std::erase_if(pts, [&](cv::Point2d p) { return std::abs(conicDistance(*conic, p)) > limit; });
  return fitEllipseConic(pts);
}

}  // namespace

CircleMarks detectCircleMarks(const cv::Mat& image, const BoardSpec& board) {
  CircleMarks out;
  const cv::Mat image8 = toGrey8(image);
  // The grid only needs to be found to within a pixel or two (each mark's rim does the rest):
  // large images are searched at half size first, where the blob search (17 thresholds) runs
  // about 4x faster; marks too small for that are searched at full size.
  const auto findGrid = [&](const cv::Mat& grey, double scale, std::vector<cv::Point2f>& found) {
    cv::SimpleBlobDetector::Params blobs;
    blobs.minArea = 20;
    blobs.maxArea = static_cast<float>(grey.total()) / static_cast<float>(board.pointCount());
    if (!cv::findCirclesGrid(grey, cv::Size(board.cols, board.rows), found,
                             cv::CALIB_CB_SYMMETRIC_GRID, cv::SimpleBlobDetector::create(blobs)))
      return false;
    // Pixel centres: pixel i of the half-size image covers full-size pixels 2i and 2i + 1.
    const auto k = static_cast<float>(scale), shift = static_cast<float>(0.5 * (scale - 1));
    for (auto& f : found) f = f * k + cv::Point2f(shift, shift);
    return true;
  };
  std::vector<cv::Point2f> found;
  bool ok = false;
  if (image8.cols > 800) {
    cv::Mat half;
    cv::resize(image8, half, {}, 0.5, 0.5, cv::INTER_AREA);
    ok = findGrid(half, 2.0, found);
  }
  if (!ok) ok = findGrid(image8, 1.0, found);
  if (!ok) {
    out.detection.status.message =
        "no grid of " + std::to_string(board.cols) + "x" + std::to_string(board.rows) +
        " circular marks found (wrong board spec, grid partly outside the image, "
        "or too blurred)";
    return out;
  }
  std::vector<cv::Point2d> coarse(found.begin(), found.end());
  toPlateOrder(board.cols, board.rows, coarse);
  const double radiusShare = board.diameterMm / (2 * board.pitchMm);
  const auto count = static_cast<std::size_t>(board.pointCount());
  std::vector<cv::Point2d> centres(count);
  std::vector<std::vector<cv::Point2d>> rims(count);
  std::vector<std::string> failures(count);  // why a mark failed (empty: it did not)
  // Marks are independent: fitted in parallel.
  cv::parallel_for_(cv::Range(0, static_cast<int>(count)), [&](const cv::Range& range) {
    for (int index = range.start; index < range.end; ++index) {
      const int r = index / board.cols, c = index % board.cols;
      const auto i = static_cast<std::size_t>(index);
      const cv::Point2d p = coarse[i];
      double spacing = 1e9;
      for (const auto& [dc, dr] : {std::pair{1, 0}, {-1, 0}, {0, 1}, {0, -1}}) {
        const int cc = c + dc, rr = r + dr;
        if (cc < 0 || rr < 0 || cc >= board.cols || rr >= board.rows) continue;
        spacing =
            std::min(spacing, cv::norm(coarse[static_cast<std::size_t>(rr * board.cols + cc)] - p));
      }
      const double largest = radiusShare * spacing * 1.6;  // the longest half-axis, with margin
      const int half = static_cast<int>(std::ceil(largest)) + 8;
      EdgeParams params;
      params.roi = cv::Rect(cvRound(p.x) - half, cvRound(p.y) - half, 2 * half + 1, 2 * half + 1);
      const EdgeContours edges = detectSubpixelEdges(image, params);
      std::vector<cv::Point2d> rim;
      for (const EdgePoint& e : edges.points) {
        const cv::Point2d d = e.position - p;
        const double dist = cv::norm(d);
        // Dark mark on a light plate: the gradient points outwards.
        if (dist < 0.3 * radiusShare * spacing || dist > largest) continue;
        if (e.normal.dot(d) / dist < 0.6) continue;
        rim.push_back(e.position);
      }
      const auto conic = robustConic(rim);
      const std::string mark = "mark (" + std::to_string(c) + ", " + std::to_string(r) + ")";
      if (!conic || rim.size() < 12) {
        failures[i] = mark + " has no clean rim (blurred, partly hidden or touching another)";
        continue;
      }
      centres[i] = conicPole(*conic, {0, 0, 1});
      if (cv::norm(centres[i] - p) > 3.0) {
        failures[i] = mark + " rim does not fit an ellipse around its blob";
        continue;
      }
      rims[i] = std::move(rim);
    }
  });
  // The first failing mark in plate order, as a serial search would name it.
  for (const std::string& why : failures)
    if (!why.empty()) {
      out.detection.status.message = why;
      return out;
    }
  out.detection.points = std::move(centres);
  out.rims = std::move(rims);
  out.detection.status = {};
  return out;
}

std::vector<cv::Point2d> perspectiveCentres(const CircleMarks& marks, const CameraModel& camera,
                                            const cv::Matx33d& R) {
  const cv::Matx33d& K = camera.cameraMatrix;
  // The plate's vanishing line: normalised directions d with n . d = 0, n = R e3; in
  // undistorted pixels u = K d it is K^-T n.
  const cv::Vec3d n(R(0, 2), R(1, 2), R(2, 2));
  const cv::Vec3d line = K.inv().t() * n;
  std::vector<cv::Point2d> centres;
  centres.reserve(marks.rims.size());
  for (std::size_t i = 0; i < marks.rims.size(); ++i) {
    std::vector<cv::Point2d> undistorted;
    undistorted.reserve(marks.rims[i].size());
    for (const auto& p : marks.rims[i]) {
      const cv::Point2d q = camera.undistort(p);
      undistorted.push_back({K(0, 0) * q.x + K(0, 1) * q.y + K(0, 2), K(1, 1) * q.y + K(1, 2)});
    }
    const auto conic = robustConic(undistorted);
    if (!conic) {
      centres.push_back(marks.detection.points[i]);
      continue;
    }
    const cv::Point2d u = conicPole(*conic, line);
    const double y = (u.y - K(1, 2)) / K(1, 1);
    const double x = (u.x - K(0, 2) - K(0, 1) * y) / K(0, 0);
    centres.push_back(camera.distort({x, y}));
  }
  return centres;
}

}  // namespace facet
