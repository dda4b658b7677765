#include "algorithms/calibration/chessboard_corners.hpp"

#include <algorithm>
#include <cmath>

#include <opencv2/calib3d.hpp>
#include <opencv2/core/utility.hpp>
#include <opencv2/imgproc.hpp>

#include "algorithms/calibration/edge_curve.hpp"
#include "algorithms/edges/subpixel_edges.hpp"
#include "algorithms/image/grey8.hpp"

namespace facet {
namespace {

// Edge points per corner that estimate its local blur width. The width barely moves a symmetric
// step's position, and a corner's strips hold a hundred or more points; fitting 64 of them with a
// free width first took a third of the detection time.
constexpr int kCornerBlurSamples = 16;

double meanGrey(const cv::Mat& image8, cv::Point2d centre, double radius) {
  const int r = std::max(1, static_cast<int>(radius));
  const cv::Rect box =
      cv::Rect(cvRound(centre.x) - r, cvRound(centre.y) - r, 2 * r + 1, 2 * r + 1) &
      cv::Rect(0, 0, image8.cols, image8.rows);
  if (box.empty()) return 128.0;
  return cv::mean(image8(box))[0];
}

// Puts OpenCV's grid into the plate's order: right-handed as seen by the camera (x right of y
// turns clockwise on screen, like the image axes), the dark outer square at the origin.
void toPlateOrder(const cv::Mat& image8, int cols, int rows, std::vector<cv::Point2d>& p) {
  auto at = [&](int c, int r) -> cv::Point2d& { return p[static_cast<std::size_t>(r * cols + c)]; };
  const cv::Point2d ex = at(1, 0) - at(0, 0), ey = at(0, 1) - at(0, 0);
  if (ex.cross(ey) < 0)
    for (int r = 0; r < rows; ++r) std::reverse(&at(0, r), &at(0, r) + cols);
  const auto outerGrey = [&](int c, int r, int dc, int dr) {
    const cv::Point2d sx = at(c + dc, r) - at(c, r), sy = at(c, r + dr) - at(c, r);
    const cv::Point2d centre = at(c, r) - 0.5 * sx - 0.5 * sy;
    return meanGrey(image8, centre, 0.15 * std::min(cv::norm(sx), cv::norm(sy)));
  };
  if (outerGrey(0, 0, 1, 1) > outerGrey(cols - 1, rows - 1, -1, -1))
    std::reverse(p.begin(), p.end());
}

// True when squares continue beyond the grid's border: the grid found is part of a larger board
// (a board spec with fewer corners than the plate has). Samples the cells one row beyond each
// side, where a right board has its plain margin; they alternate on a larger board.
bool squaresBeyondBorder(const cv::Mat& image8, int cols, int rows,
                         const std::vector<cv::Point2d>& p) {
  auto at = [&](int c, int r) { return p[static_cast<std::size_t>(r * cols + c)]; };
  const double dark = meanGrey(image8, (at(0, 0) + at(1, 1)) / 2, 2);
  const double light = meanGrey(image8, (at(1, 0) + at(2, 1)) / 2, 2);
  const double contrast = std::abs(light - dark);
  const cv::Rect inside(2, 2, image8.cols - 4, image8.rows - 4);
  // A side: corners a(i) along the border, b(i) their neighbours one row inwards.
  const auto side = [&](auto a, auto b, int n) {
    double lo = 1e9, hi = -1e9;
    for (int i = 0; i + 1 < n; ++i) {
      const cv::Point2d edge = (a(i) + a(i + 1)) / 2, inner = (b(i) + b(i + 1)) / 2;
      const cv::Point2d beyond = edge + 1.5 * (edge - inner);
      if (!inside.contains(cv::Point(cvRound(beyond.x), cvRound(beyond.y)))) continue;
      const double g = meanGrey(image8, beyond, 0.15 * cv::norm(edge - inner));
      lo = std::min(lo, g), hi = std::max(hi, g);
    }
    return hi > lo && hi - lo > 0.5 * contrast;
  };
  return side([&](int i) { return at(i, 0); }, [&](int i) { return at(i, 1); }, cols) ||
         side([&](int i) { return at(i, rows - 1); }, [&](int i) { return at(i, rows - 2); },
              cols) ||
         side([&](int i) { return at(0, i); }, [&](int i) { return at(1, i); }, rows) ||
         side([&](int i) { return at(cols - 1, i); }, [&](int i) { return at(cols - 2, i); }, rows);
}

// OpenCV's saddle-point refinement (cornerSubPix) in a window that stays inside the corner's
// four squares. For squares too small to leave clean edge points between the junctions: it
// shifts a little with the blur and the X's perspective angle, but a plate seen small is still
// usable (OpenCV's own pipeline is no better there).
cv::Point2d saddleCorner(const cv::Mat& grey32, cv::Point2d p, double spacing, double sine) {
  const int half = std::clamp(static_cast<int>(0.5 * spacing * sine) - 1, 2, 10);
  std::vector<cv::Point2f> one{cv::Point2f(p)};
  cv::cornerSubPix(grey32, one, {half, half}, {-1, -1},
                   {cv::TermCriteria::EPS + cv::TermCriteria::COUNT, 50, 1e-4});
  return one.front();
}

}  // namespace

Status<CalibrationFailure> refineChessboardCorners(const cv::Mat& image, int cols, int rows,
                                                   std::vector<cv::Point2d>& corners,
                                                   int* saddleCorners) {
  if (saddleCorners) *saddleCorners = 0;
  auto at = [&](int c, int r) { return corners[static_cast<std::size_t>(r * cols + c)]; };
  const std::size_t count = corners.size();
  if (count == 0) return {};

  // The image's edge blur and Canny thresholds, once, around the first corner: they decide how
  // far from a junction edge points are clean; each corner's profile fits estimate their own.
  EdgeParams probeParams;
  {
    const cv::Point2d p = at(0, 0), q = cols > 1 ? at(1, 0) : at(0, std::min(1, rows - 1));
    const int probe = std::max(8, static_cast<int>(std::ceil(0.5 * cv::norm(q - p))));
    probeParams.roi =
        cv::Rect(cvRound(p.x) - probe, cvRound(p.y) - probe, 2 * probe + 1, 2 * probe + 1);
  }
  const EdgeContours probe = detectSubpixelEdges(image, probeParams);
  const double blurSigma = probe.blurSigma;
  cv::Mat grey32;
  image.convertTo(grey32, CV_32F);  // for the saddle points

  std::vector<cv::Point2d> refined(count);
  std::vector<Status<CalibrationFailure>> status(count);
  std::vector<char> bySaddle(count, 0);
  // Corners are independent: refined in parallel.
  cv::parallel_for_(cv::Range(0, static_cast<int>(count)), [&](const cv::Range& range) {
    for (int index = range.start; index < range.end; ++index) {
      const int r = index / cols, c = index % cols;
      const auto i = static_cast<std::size_t>(index);
      const cv::Point2d p = at(c, r);
      const cv::Point2d xa = c > 0 ? at(c - 1, r) : p, xb = c + 1 < cols ? at(c + 1, r) : p;
      const cv::Point2d ya = r > 0 ? at(c, r - 1) : p, yb = r + 1 < rows ? at(c, r + 1) : p;
      double spacing = 1e9;
      for (const cv::Point2d& n : {xa, xb, ya, yb})
        if (n != p) spacing = std::min(spacing, cv::norm(n - p));
      const cv::Point2d dx = (xb - xa) / cv::norm(xb - xa), dy = (yb - ya) / cv::norm(yb - ya);
      const double sine = std::max(std::abs(dx.cross(dy)), 0.3);
      // The edges' profile fit looks up to 6.5 px across and 3 px along an edge, and the blurred
      // X bends the edges out to about 3 sigma from the junction: edge points of one line are
      // clean where the other line (at the corner, and at the neighbouring corners) is farther
      // than that, measured across the narrower of the X's angles.
      const double inner = (6.75 + 3.0 * blurSigma) / sine + 1.0;
      const double outer = spacing - inner;
      // Squares a few blur widths across still show the X's saddle; below that nothing in the
      // image locates the corner.
      const bool saddleVisible = 4.0 * blurSigma < spacing * sine;
      if (outer < inner + 4.0) {
        if (saddleVisible) {
          refined[i] = saddleCorner(grey32, p, spacing, sine);
          bySaddle[i] = 1;
        } else {
          status[i] = Status<CalibrationFailure>::failed(
              CalibrationFailure::PatternNotFound,
              "squares too small for the blur (" + std::to_string(spacing) +
                  " px between corners, edge blur sigma " + std::to_string(blurSigma) + " px)");
        }
        continue;
      }
      // Only the two lines' clean stretches are searched: a strip along each, without the
      // junction (most of the box around the corner is other squares' edges).
      const int half = static_cast<int>(std::ceil(outer)) + 1;
      EdgeParams params;
      params.roi = cv::Rect(cvRound(p.x) - half, cvRound(p.y) - half, 2 * half + 1, 2 * half + 1);
      params.low = probe.lowThreshold;
      params.high = probe.highThreshold;
      params.blurOnPixelGrid = probe.blurOnPixelGrid;  // one optics per image: its width is fitted
      params.blurSamples = kCornerBlurSamples;
      // The mask covers only the ROI (drawn in its coordinates).
      params.mask = cv::Mat::zeros(params.roi.size(), CV_8U);
      const cv::Point2d local = p - cv::Point2d(params.roi.tl());
      for (const cv::Point2d& d : {dx, dy})
        cv::line(params.mask, local - (outer + 2) * d, local + (outer + 2) * d, cv::Scalar(255), 9);
      cv::circle(params.mask, local, std::max(0, static_cast<int>(inner) - 2), cv::Scalar(0), -1);
      const EdgeContours edges = detectSubpixelEdges(image, params);
      EdgeCurve lx{p, dx, {-dx.y, dx.x}}, ly{p, dy, {-dy.y, dy.x}};
      std::vector<cv::Point2d> onX, onY;
      for (const EdgePoint& e : edges.points) {
        const cv::Point2d d = e.position - p;
        const double dist = cv::norm(d);
        if (dist < inner || dist > outer) continue;
        // An edge point of the line along dx has its normal across dx, and lies near that line.
        if (std::abs(e.normal.dot(dx)) < 0.34 && std::abs(d.dot(lx.across)) < 2.5)
          onX.push_back(e.position);
        else if (std::abs(e.normal.dot(dy)) < 0.34 && std::abs(d.dot(ly.across)) < 2.5)
          onY.push_back(e.position);
      }
      std::optional<cv::Point2d> q;
      if (fitEdgeCurve(onX, lx) && fitEdgeCurve(onY, ly)) q = intersectEdgeCurves(lx, ly, p);
      if (q && cv::norm(*q - p) <= 2.0) {
        refined[i] = *q;
      } else if (saddleVisible && outer < 2.0 * inner) {
        // Squares just above the size for edge lines: too few clean points at this angle.
        refined[i] = saddleCorner(grey32, p, spacing, sine);
        bySaddle[i] = 1;
      } else {
        status[i] = Status<CalibrationFailure>::failed(
            CalibrationFailure::PatternNotFound,
            "corner (" + std::to_string(c) + ", " + std::to_string(r) +
                ") has too few clean edge points on its two lines (blurred or partly hidden?)");
      }
    }
  });
  for (const auto& s : status)
    if (!s.ok()) return s;
  if (saddleCorners)
    *saddleCorners = static_cast<int>(std::count(bySaddle.begin(), bySaddle.end(), 1));
  corners = std::move(refined);
  return {};
}

PatternDetection detectChessboard(const cv::Mat& image, const BoardSpec& board) {
  PatternDetection out;
  const cv::Mat image8 = toGrey8(image);
  // The grid only needs to be found to within a pixel or two (the refinement does the rest):
  // large images are searched at half size, where OpenCV's detectors run about 4x faster.
  const bool halve = image8.cols > 800;
  cv::Mat coarse = image8;
  if (halve) cv::resize(image8, coarse, {}, 0.5, 0.5, cv::INTER_AREA);
  std::vector<cv::Point2f> found;
  const cv::Size grid(board.cols, board.rows);
  bool ok = cv::findChessboardCorners(
      coarse, grid, found,
      cv::CALIB_CB_ADAPTIVE_THRESH | cv::CALIB_CB_NORMALIZE_IMAGE | cv::CALIB_CB_FAST_CHECK);
  if (!ok) ok = cv::findChessboardCornersSB(coarse, grid, found, cv::CALIB_CB_NORMALIZE_IMAGE);
  if (ok && halve)
    for (auto& f : found) f = f * 2.0f + cv::Point2f(0.5f, 0.5f);
  if (!ok) {
    out.status.message =
        "no chessboard of " + std::to_string(board.cols) + "x" + std::to_string(board.rows) +
        " inner corners found (wrong board spec, board partly outside the image, or too "
        "blurred)";
    return out;
  }
  out.points.assign(found.begin(), found.end());
  if (squaresBeyondBorder(image8, board.cols, board.rows, out.points)) {
    out.points.clear();
    out.status.message = "the plate has more squares than " + std::to_string(board.cols) + "x" +
                         std::to_string(board.rows) + " inner corners (is the board spec right?)";
    return out;
  }
  toPlateOrder(image8, board.cols, board.rows, out.points);
  int saddle = 0;
  out.status = refineChessboardCorners(image, board.cols, board.rows, out.points, &saddle);
  if (!out.status.ok()) out.points.clear();
  if (out.status.ok() && saddle > 0)
    out.note = std::to_string(saddle) + " of " + std::to_string(out.points.size()) +
               " corners by saddle point: squares too small for edge lines at this blur and "
               "angle (a closer or larger plate is more precise)";
  return out;
}

}  // namespace facet
