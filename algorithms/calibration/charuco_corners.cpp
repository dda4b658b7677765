#include "algorithms/calibration/charuco_corners.hpp"

#include <algorithm>
#include <cmath>
#include <numeric>
#include <set>

#include <opencv2/aruco/charuco.hpp>
#include <opencv2/core/utility.hpp>
#include <opencv2/imgproc.hpp>

#include "algorithms/calibration/edge_curve.hpp"
#include "algorithms/image/grey8.hpp"
#include "algorithms/measure/grey_profile.hpp"
#include "algorithms/measure/measuring_path.hpp"
#include "algorithms/measure/profile_edges.hpp"

namespace facet {
namespace {

// Fewest corners a view is kept with: the solver's first guess of a view's pose is a homography,
// and a handful of corners more than its four keep that guess from following the noise.
constexpr int kMinCorners = 8;
// Pixels across the edge line (along it, for the profile) that a profile averages.
constexpr double kProfileWidth = 2.0;
// The coarse corner is within a few tenths of a pixel: an edge farther than this from the line
// through it belongs to something else (the marker's border, a neighbouring square).
constexpr double kEdgeReach = 2.0;
// The step fit's reach either side of an edge (ProfileEdgeParams::window), beyond kEdgeReach.
constexpr double kFitReach = kEdgeReach + 8.0;

// The grid's directions and square size in the image at one corner: an affine fit to the coarse
// corners within two squares of it (a lens-distorted grid is locally affine).
struct LocalGrid {
  cv::Point2d dx, dy;           // unit directions of the plate's x and y
  double stepX = 0, stepY = 0;  // one square along them, pixels
};

bool localGrid(const std::vector<cv::Point2d>& points, const std::vector<int>& ids, int cols,
               std::size_t self, LocalGrid& grid) {
  const int c = ids[self] % cols, r = ids[self] / cols;
  cv::Matx22d normal = cv::Matx22d::zeros();
  cv::Matx22d moment = cv::Matx22d::zeros();  // sum of (image offset) (plate offset)^T
  for (std::size_t j = 0; j < points.size(); ++j) {
    const int dc = ids[j] % cols - c, dr = ids[j] / cols - r;
    if (j == self || std::abs(dc) > 2 || std::abs(dr) > 2) continue;
    const cv::Vec2d u(dc, dr);
    const cv::Point2d d = points[j] - points[self];
    normal += u * u.t();
    moment += cv::Vec2d(d.x, d.y) * u.t();
  }
  if (cv::determinant(normal) < 1.0) return false;  // neighbours on one line only
  const cv::Matx22d a = moment * normal.inv();      // columns: one square along x, along y
  const cv::Point2d ax(a(0, 0), a(1, 0)), ay(a(0, 1), a(1, 1));
  grid.stepX = cv::norm(ax), grid.stepY = cv::norm(ay);
  if (grid.stepX < 1 || grid.stepY < 1) return false;
  grid.dx = ax / grid.stepX, grid.dy = ay / grid.stepY;
  return true;
}

// Edge points of one stretch of an edge line: profiles laid along `across` (the other line's
// direction at the corner, so that each profile keeps its distance from that line) at distances
// `from`..`to` from `origin` along `along`.
std::vector<cv::Point2d> stretchEdgePoints(const cv::Mat& image, cv::Point2d origin,
                                           cv::Point2d along, cv::Point2d across, double from,
                                           double to, double halfLength,
                                           const ProfileEdgeParams& params) {
  std::vector<cv::Point2d> out;
  GreyProfileSampler sampler;
  ProfileEdgeFinder finder(params);
  const double angle = std::atan2(-across.y, across.x) * 180.0 / CV_PI;
  // Profiles kProfileWidth apart are independent; at most a dozen a stretch is plenty.
  const double step = std::max(kProfileWidth, (to - from) / 12.0);
  for (double t = from; t <= to + 1e-9; t += step) {
    const cv::Point2d centre = origin + t * along;
    const MeasuringPath path(
        MeasuringRect{centre.x, centre.y, 2 * halfLength, kProfileWidth, angle});
    const GreyProfile& profile = sampler.sample(image, path);
    // A profile cut short by the image's border still serves while it holds a step fit's window
    // either side of the line.
    if (profile.values.empty() ||
        (profile.partial && (profile.start > -kFitReach || profile.end() < kFitReach)))
      continue;
    const ProfileEdge* nearest = nullptr;
    for (const ProfileEdge& e : finder.find(profile))
      if (std::abs(e.position) <= kEdgeReach &&
          (!nearest || std::abs(e.position) < std::abs(nearest->position)))
        nearest = &e;
    if (nearest) out.push_back(path.at(nearest->position, 0));
  }
  return out;
}

// The blur width of the edges around a corner (fitted step width, pixels), from one profile
// across the x line halfway to the next corner; 1.5 px when none is found.
double localBlur(const cv::Mat& image, cv::Point2d corner, const LocalGrid& g,
                 const ProfileEdgeParams& params) {
  const cv::Point2d centre = corner + 0.5 * g.stepX * g.dx;
  const double angle = std::atan2(-g.dy.y, g.dy.x) * 180.0 / CV_PI;
  const MeasuringPath path(MeasuringRect{centre.x, centre.y, 0.8 * g.stepY, kProfileWidth, angle});
  const GreyProfile profile = sampleGreyProfile(image, path);
  double blur = 1.5, best = kEdgeReach;
  if (profile.partial || profile.values.empty()) return blur;
  for (const ProfileEdge& e : findProfileEdges(profile, params))
    if (std::abs(e.position) <= best) best = std::abs(e.position), blur = e.blur;
  return blur;
}

// What a corner's refinement needs to know of its surroundings.
struct CornerSetup {
  enum class Kind { EdgeLines, Saddle, Dropped } kind = Kind::Dropped;
  LocalGrid grid;
  double sine = 1;   // of the X's angle
  double inner = 0;  // nearest a profile comes to the corner, along a line, pixels
  ProfileEdgeParams params;
};

CornerSetup setUpCorner(const cv::Mat& image, const cv::Mat& image8, const LocalGrid& g,
                        cv::Point2d corner) {
  CornerSetup setup;
  setup.grid = g;
  setup.sine = std::max(std::abs(g.dx.cross(g.dy)), 0.3);
  // Steps below a third of the local contrast are marker bits' blur or noise, not the edge.
  const double reach = 0.5 * std::min(g.stepX, g.stepY);
  const cv::Rect box = cv::Rect(cvRound(corner.x - reach), cvRound(corner.y - reach),
                                cvRound(2 * reach) + 1, cvRound(2 * reach) + 1) &
                       cv::Rect(0, 0, image8.cols, image8.rows);
  if (box.area() < 9) return setup;
  double lo = 0, hi = 0;
  cv::minMaxLoc(image8(box), &lo, &hi);
  setup.params.minAmplitude = std::max(8.0, (hi - lo) / 3.0);
  const double blur = localBlur(image, corner, g, setup.params);
  // A profile parallel to the other line stays clear of that line's blur (3.5 widths) and of
  // its own width's half, measured across the narrower angle of the X.
  setup.inner = (3.5 * blur + 0.5 * kProfileWidth) / setup.sine + 1.0;
  const double outer = std::min(g.stepX, g.stepY) - setup.inner;
  setup.kind = outer < setup.inner + 4.0 ? CornerSetup::Kind::Saddle : CornerSetup::Kind::EdgeLines;
  return setup;
}

// One stretch of edge line beside a corner: to the neighbouring corner (shared by the two, and
// searched once), or, with no neighbour found, one square's length out from the corner.
struct Stretch {
  std::size_t corner = 0;
  int neighbour = -1;  // index into the corners, or -1
  bool alongX = true;  // part of the corner's x line (else its y line)
  double sign = 1;     // direction from the corner: +x / +y or -x / -y
  std::vector<cv::Point2d> points;
};

void searchStretch(const cv::Mat& image, const std::vector<cv::Point2d>& corners,
                   const std::vector<CornerSetup>& setups, Stretch& s) {
  const CornerSetup& a = setups[s.corner];
  const LocalGrid& g = a.grid;
  const cv::Point2d origin = corners[s.corner];
  // Each profile runs to the middle of the squares on either side of its line: it takes in the
  // marker's border beside the edge (a neighbouring step for the estimator), never another line.
  cv::Point2d along = s.sign * (s.alongX ? g.dx : g.dy), across = s.alongX ? g.dy : g.dx;
  double halfLength = 0.5 * (s.alongX ? g.stepY : g.stepX) * a.sine;
  double from = a.inner, to = (s.alongX ? g.stepX : g.stepY) - a.inner;
  ProfileEdgeParams params = a.params;
  if (s.neighbour >= 0) {
    const auto j = static_cast<std::size_t>(s.neighbour);
    const CornerSetup& b = setups[j];
    const cv::Point2d span = corners[j] - origin;
    along = span / cv::norm(span);
    const cv::Point2d acrossB = s.alongX ? b.grid.dy : b.grid.dx;
    across = (across + acrossB) / cv::norm(across + acrossB);
    halfLength = std::min(halfLength, 0.5 * (s.alongX ? b.grid.stepY : b.grid.stepX) * b.sine);
    to = cv::norm(span) - b.inner;
    params.minAmplitude = std::min(params.minAmplitude, b.params.minAmplitude);
  }
  s.points = stretchEdgePoints(image, origin, along, across, from, to, halfLength, params);
}

// OpenCV interpolates a corner only from two whole markers beside it, so along the image's border
// (and beside a hidden marker) a ring of corners in view goes missing. Each is predicted one
// square on from two found neighbours in its row or column (the mean of the predictions there
// are); the edge-line refinement then keeps those whose lines are there, as for any corner.
// Appended after the interpolated corners, in no particular order of ids.
void addPredictedCorners(const BoardSpec& board, cv::Size size, std::vector<cv::Point2d>& points,
                         std::vector<int>& ids) {
  std::vector<int> indexOf(static_cast<std::size_t>(board.pointCount()), -1);
  for (std::size_t k = 0; k < ids.size(); ++k) indexOf[static_cast<std::size_t>(ids[k])] = int(k);
  const auto found = [&](int c, int r) -> const cv::Point2d* {
    if (c < 0 || r < 0 || c >= board.cols || r >= board.rows) return nullptr;
    const int k = indexOf[static_cast<std::size_t>(r * board.cols + c)];
    return k < 0 ? nullptr : &points[static_cast<std::size_t>(k)];
  };
  const cv::Rect2d inside(4, 4, size.width - 9, size.height - 9);
  std::vector<cv::Point2d> predicted;
  std::vector<int> predictedIds;
  for (int r = 0; r < board.rows; ++r)
    for (int c = 0; c < board.cols; ++c) {
      if (found(c, r)) continue;
      cv::Point2d sum(0, 0);
      int n = 0;
      for (const auto& [dc, dr] : {std::pair{1, 0}, {-1, 0}, {0, 1}, {0, -1}}) {
        const cv::Point2d *near = found(c + dc, r + dr), *far = found(c + 2 * dc, r + 2 * dr);
        if (near && far) sum += 2 * *near - *far, ++n;
      }
      if (n == 0 || !inside.contains(sum / n)) continue;
      predicted.push_back(sum / n);
      predictedIds.push_back(r * board.cols + c);
    }
  points.insert(points.end(), predicted.begin(), predicted.end());
  ids.insert(ids.end(), predictedIds.begin(), predictedIds.end());
}

}  // namespace

PatternDetection detectCharuco(const cv::Mat& image, const BoardSpec& board) {
  PatternDetection out;
  const cv::Mat image8 = toGrey8(image);
  const auto dictionary = cv::aruco::getPredefinedDictionary(board.dictionary);
  const auto cvBoard = cv::aruco::CharucoBoard::create(
      board.cols + 1, board.rows + 1, static_cast<float>(board.pitchMm),
      static_cast<float>(board.markerMm), dictionary);
  std::vector<std::vector<cv::Point2f>> markers, kept;
  std::vector<int> markerIds, keptIds;
  cv::aruco::detectMarkers(image8, dictionary, markers, markerIds);
  // Markers of the dictionary that are not on this board (another board in view, or the spec
  // names fewer squares than the plate has) would be matched to the wrong squares.
  const int boardMarkers = static_cast<int>(cvBoard->ids.size());
  int foreign = 0;
  for (std::size_t i = 0; i < markers.size(); ++i) {
    if (markerIds[i] >= 0 && markerIds[i] < boardMarkers)
      kept.push_back(markers[i]), keptIds.push_back(markerIds[i]);
    else
      ++foreign;
  }
  if (kept.empty()) {
    out.status.message = markers.empty()
                             ? "no " + dictionaryName(board.dictionary) +
                                   " markers found (wrong dictionary, or the board is too blurred "
                                   "or too small in the image)"
                             : std::to_string(foreign) + " markers found, none of them on a " +
                                   board.text() + " board (is the board spec right?)";
    return out;
  }
  if (foreign > static_cast<int>(kept.size())) {
    out.status.message = std::to_string(foreign) + " of " + std::to_string(markers.size()) +
                         " markers found have ids beyond the " + std::to_string(boardMarkers) +
                         " of a " + board.text() + " board (is the board spec right?)";
    return out;
  }
  std::vector<cv::Point2f> coarse;
  std::vector<int> coarseIds;
  cv::aruco::interpolateCornersCharuco(kept, keptIds, image8, cvBoard, coarse, coarseIds);
  // In the order of the ids, so that what follows (which end of a stretch searches it, the sums
  // of a corner's neighbours) does not depend on the order OpenCV returns them in.
  std::vector<std::size_t> order(coarse.size());
  std::iota(order.begin(), order.end(), 0);
  std::sort(order.begin(), order.end(),
            [&](std::size_t a, std::size_t b) { return coarseIds[a] < coarseIds[b]; });
  std::vector<cv::Point2d> points;
  std::vector<int> ids;
  for (std::size_t i : order) points.emplace_back(coarse[i]), ids.push_back(coarseIds[i]);
  const std::size_t interpolated = points.size();
  addPredictedCorners(board, image.size(), points, ids);

  // Each corner's surroundings; then the stretches of edge line between and beside corners,
  // each searched once (a stretch between two corners serves both); then each corner where its
  // two lines cross.
  std::vector<CornerSetup> setups(points.size());
  cv::parallel_for_(cv::Range(0, static_cast<int>(points.size())), [&](const cv::Range& range) {
    for (int i = range.start; i < range.end; ++i) {
      const auto k = static_cast<std::size_t>(i);
      LocalGrid g;
      if (localGrid(points, ids, board.cols, k, g))  // else isolated: no directions
        setups[k] = setUpCorner(image, image8, g, points[k]);
    }
  });
  std::vector<int> indexOf(static_cast<std::size_t>(board.pointCount()), -1);
  for (std::size_t k = 0; k < ids.size(); ++k) indexOf[static_cast<std::size_t>(ids[k])] = int(k);
  std::vector<Stretch> stretches;
  for (std::size_t k = 0; k < points.size(); ++k) {
    if (setups[k].kind != CornerSetup::Kind::EdgeLines) continue;
    const int c = ids[k] % board.cols, r = ids[k] / board.cols;
    for (const auto& [dc, dr] : {std::pair{1, 0}, {-1, 0}, {0, 1}, {0, -1}}) {
      const int nc = c + dc, nr = r + dr;
      int j = -1;
      if (nc >= 0 && nr >= 0 && nc < board.cols && nr < board.rows)
        j = indexOf[static_cast<std::size_t>(nr * board.cols + nc)];
      if (j >= 0 && setups[static_cast<std::size_t>(j)].kind != CornerSetup::Kind::EdgeLines)
        j = -1;
      if (j >= 0 && static_cast<std::size_t>(j) < k) continue;  // searched from the other end
      stretches.push_back({k, j, dr == 0, dc + dr > 0 ? 1.0 : -1.0, {}});
    }
  }
  cv::parallel_for_(cv::Range(0, static_cast<int>(stretches.size())), [&](const cv::Range& range) {
    for (int i = range.start; i < range.end; ++i)
      searchStretch(image, points, setups, stretches[static_cast<std::size_t>(i)]);
  });
  std::vector<std::vector<cv::Point2d>> onX(points.size()), onY(points.size());
  for (const Stretch& s : stretches) {
    auto& line = s.alongX ? onX : onY;
    line[s.corner].insert(line[s.corner].end(), s.points.begin(), s.points.end());
    if (s.neighbour >= 0) {
      auto& other = line[static_cast<std::size_t>(s.neighbour)];
      other.insert(other.end(), s.points.begin(), s.points.end());
    }
  }
  int saddle = 0;
  for (std::size_t k = 0; k < points.size(); ++k) {
    const CornerSetup& setup = setups[k];
    if (setup.kind == CornerSetup::Kind::Dropped) continue;
    // A predicted corner has no position but its lines': located by them, or not at all.
    if (k >= interpolated && setup.kind != CornerSetup::Kind::EdgeLines) continue;
    cv::Point2d corner = points[k];  // Saddle: OpenCV's cornerSubPix position
    if (setup.kind == CornerSetup::Kind::EdgeLines) {
      const LocalGrid& g = setup.grid;
      EdgeCurve lx{corner, g.dx, {-g.dx.y, g.dx.x}}, ly{corner, g.dy, {-g.dy.y, g.dy.x}};
      if (!fitEdgeCurve(onX[k], lx) || !fitEdgeCurve(onY[k], ly)) continue;
      const auto q = intersectEdgeCurves(lx, ly, corner);
      if (!q || cv::norm(*q - corner) > kEdgeReach) continue;
      corner = *q;
    } else {
      ++saddle;
    }
    out.points.push_back(corner);
    out.ids.push_back(ids[k]);
  }
  // In the order of the ids (the predicted corners came last).
  std::vector<std::size_t> byId(out.ids.size());
  std::iota(byId.begin(), byId.end(), 0);
  std::sort(byId.begin(), byId.end(),
            [&](std::size_t a, std::size_t b) { return out.ids[a] < out.ids[b]; });
  std::vector<cv::Point2d> sortedPoints;
  std::vector<int> sortedIds;
  for (std::size_t i : byId) sortedPoints.push_back(out.points[i]), sortedIds.push_back(out.ids[i]);
  out.points = std::move(sortedPoints), out.ids = std::move(sortedIds);
  const int total = board.pointCount(), found = static_cast<int>(out.ids.size());
  std::set<int> cols, rows;
  for (int id : out.ids) cols.insert(id % board.cols), rows.insert(id / board.cols);
  if (found < kMinCorners || cols.size() < 2 || rows.size() < 2) {
    out.status.message =
        "only " + std::to_string(found) + " of " + std::to_string(total) + " corners located (" +
        std::to_string(kept.size()) + " markers found; at least " + std::to_string(kMinCorners) +
        " corners over two rows and columns are needed" +
        (kept.size() >= 4 && found < 4 ? "; do the squares and markers match the board spec?"
                                       : "") +
        ")";
    out.points.clear(), out.ids.clear();
    return out;
  }
  out.status = {};
  if (found < total)
    out.note = std::to_string(found) + " of " + std::to_string(total) +
               " corners (part of the plate outside the image or hidden)";
  if (saddle > 0)
    out.note += std::string(out.note.empty() ? "" : "; ") + std::to_string(saddle) + " of " +
                std::to_string(found) +
                " corners by saddle point: squares too small for edge lines at this blur and "
                "angle (a closer or larger plate is more precise)";
  return out;
}

}  // namespace facet
