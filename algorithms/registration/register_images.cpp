#include "algorithms/registration/register_images.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <optional>

#include <opencv2/imgproc.hpp>

#include "algorithms/image/grey_image.hpp"
#include "algorithms/registration/correlation_peak.hpp"
#include "algorithms/registration/harris_affine.hpp"
#include "algorithms/registration/patch_correlation.hpp"
#include "algorithms/registration/relative_defocus.hpp"
#include "algorithms/registration/rotation_scale_vote.hpp"

namespace facet {
namespace {

// Grey on [0, 1] as float, whatever the input's depth.
cv::Mat unitGrey(const cv::Mat& image) {
  const cv::Mat grey = toGrey(image);
  double scale = 1.0, offset = 0.0;
  if (grey.depth() == CV_8U) {
    scale = 1.0 / 255.0;
  } else if (grey.depth() == CV_16U) {
    scale = 1.0 / 65535.0;
  } else {
    // Other depths (float, signed): brought to [0, 1] by their own range when outside it.
    double lo = 0, hi = 0;
    cv::minMaxLoc(grey, &lo, &hi);
    if ((hi > 1.0 || lo < 0.0) && hi > lo) {
      scale = 1.0 / (hi - lo);
      offset = -lo * scale;
    }
  }
  cv::Mat out;
  grey.convertTo(out, CV_32F, scale, offset);
  return out;
}

bool isBlank(const cv::Mat& grey) {
  cv::Scalar mean, stddev;
  cv::meanStdDev(grey, mean, stddev);
  return stddev[0] < 1e-3;
}

// One image's regions and windows for one detector, described lazily in the corners' spreading
// order.
struct Features {
  int described = 0;                  // corners [0, described) have been turned into windows
  std::vector<AffineRegion> regions;  // only those with a valid window
  std::vector<LogPolarWindow> windows;
  std::vector<int> ranks;  // the corner's position in spreading order
};

// Regions (adapted when asked) and windows of the corners up to rank `count`; lazily, so that
// the corners kept for escalation cost nothing unless it happens.
void describeUpTo(Features& f, const std::vector<HarrisCorner>& corners,
                  const std::vector<cv::Mat>& pyramid, const RegistrationParams& params,
                  int count) {
  const int end = std::min(count, static_cast<int>(corners.size()));
  for (int i = f.described; i < end; ++i) {
    const HarrisCorner& c = corners[i];
    AffineRegion r{c.pt, cv::Matx22d(c.scale, 0, 0, c.scale), c.response};
    if (params.affineRegions) {
      const std::vector<AffineRegion> adapted = adaptAffineRegions(pyramid, {c});
      if (adapted.empty()) continue;
      r = adapted.front();
    }
    LogPolarWindow w = sampleLogPolar(pyramid, r.pt, r.shape, params.window);
    if (!w.valid) continue;
    f.regions.push_back(r);
    f.windows.push_back(std::move(w));
    f.ranks.push_back(i);
  }
  f.described = std::max(f.described, end);
}

double rotationDegOf(const cv::Matx22d& L) {
  // Pose2D convention: R(a) = [[cos a, sin a], [-sin a, cos a]].
  return atan2(L(0, 1) - L(1, 0), L(0, 0) + L(1, 1)) * 180.0 / std::numbers::pi;
}

// Local linear map ref offsets -> image offsets of a window match:
// L = ringRatio^s * shape_img * Rot(2 pi t / angles) * shape_ref^-1.
cv::Matx22d localMap(const AffineRegion& ref, const AffineRegion& img, const WindowScore& s,
                     const LogPolarParams& lp) {
  const double a = 2.0 * std::numbers::pi * s.angleShift / lp.angles;
  const cv::Matx22d rot(std::cos(a), -std::sin(a), std::sin(a), std::cos(a));
  return std::pow(lp.ringRatio, s.ringShift) * img.shape * rot * ref.shape.inv();
}

cv::Matx22d jacobianAt(const cv::Matx33d& H, cv::Point2d p) {
  const double w = H(2, 0) * p.x + H(2, 1) * p.y + H(2, 2);
  const cv::Point2d q = mapPoint(H, p);
  const double u = q.x, v = q.y;
  return {(H(0, 0) - u * H(2, 0)) / w, (H(0, 1) - u * H(2, 1)) / w, (H(1, 0) - v * H(2, 0)) / w,
          (H(1, 1) - v * H(2, 1)) / w};
}

// The linear scale by which H magnifies the neighbourhood of p (square root of the area ratio).
double magnificationAt(const cv::Matx33d& H, cv::Point2d p) {
  return std::sqrt(std::abs(cv::determinant(jacobianAt(H, p))));
}

cv::Point2d centreOf(const cv::Mat& image) {
  return {(image.cols - 1) / 2.0, (image.rows - 1) / 2.0};
}

// What the re-matching passes of one pair share: the two views brought to the same resolution
// and focus on the first pass (properties of the pair, not of the pass), and the buffers each
// pass warps into (a fresh view-sized image per pass costs its page faults every time).
struct RematchViews {
  cv::Mat ref, img;               // at matched resolution; img also at matched focus
  std::optional<double> defocus;  // relative_defocus.hpp; estimated on the first pass
  cv::Mat ones, warped, valid, focused;
};

// Warp-and-re-match: the reference warped by H is compared, patch by patch around each reference
// corner's predicted position, with the image; the NCC peak (subpixel) gives the match.
std::vector<FeatureMatch> rematch(const cv::Mat& refGrey, const cv::Mat& imgGrey,
                                  const std::vector<HarrisCorner>& corners, const cv::Matx33d& H,
                                  int R, const RegistrationParams& params, RematchViews& v) {
  if (v.ref.empty()) {
    // Match resolutions: blur whichever image is seen at the finer scale, into a buffer of its
    // own (a blur into `ref` or `img` while they share the caller's pixels would blur those in
    // place).
    const double s = magnificationAt(H, centreOf(refGrey));
    v.ref = refGrey;
    v.img = imgGrey;
    if (s < 0.8) {
      const double sigma = 0.5 * std::sqrt(1.0 / (s * s) - 1.0);
      cv::Mat blurred;
      cv::GaussianBlur(refGrey, blurred, cv::Size(), sigma, sigma, cv::BORDER_REFLECT);
      v.ref = blurred;
    } else if (s > 1.25) {
      const double sigma = 0.5 * std::sqrt(s * s - 1.0);
      cv::Mat blurred;
      cv::GaussianBlur(imgGrey, blurred, cv::Size(), sigma, sigma, cv::BORDER_REFLECT);
      v.img = blurred;
    }
    v.ones.create(refGrey.size(), CV_8U);
    v.ones.setTo(255);
  }
  cv::warpPerspective(v.ref, v.warped, H, imgGrey.size(), cv::INTER_LINEAR, cv::BORDER_CONSTANT,
                      -1);
  cv::warpPerspective(v.ones, v.valid, H, imgGrey.size(), cv::INTER_NEAREST, cv::BORDER_CONSTANT,
                      0);
  // The views may also differ in focus (a refocused lens, a blurred shot): the sharper one is
  // blurred to the other's detail, estimated on the first re-matching (relative_defocus.hpp).
  if (!v.defocus) {
    v.defocus = params.matchDefocus ? relativeDefocus(v.warped, v.img, v.valid) : 0.0;
    if (*v.defocus < 0) {
      cv::Mat blurred;
      cv::GaussianBlur(v.img, blurred, cv::Size(), -*v.defocus, -*v.defocus, cv::BORDER_REFLECT);
      v.img = blurred;
    }
  }
  const cv::Mat& img = v.img;
  cv::Mat warped = v.warped, valid = v.valid;
  if (*v.defocus > 0) {
    cv::GaussianBlur(v.warped, v.focused, cv::Size(), *v.defocus, *v.defocus, cv::BORDER_REFLECT);
    warped = v.focused;
    // The blur has spread the unmapped border into the pixels within 3 sigma of it.
    const int reach = static_cast<int>(std::ceil(3 * *v.defocus));
    cv::erode(v.valid, v.valid,
              cv::getStructuringElement(cv::MORPH_RECT, {2 * reach + 1, 2 * reach + 1}));
  }
  const int r = params.refinePatchRadius;
  const cv::Rect bounds(0, 0, imgGrey.cols, imgGrey.rows);
  std::vector<FeatureMatch> out;
  cv::Mat result;
  for (const HarrisCorner& c : corners) {
    const cv::Point2d q = mapPoint(H, c.pt);
    if (!std::isfinite(q.x) || !std::isfinite(q.y)) continue;
    const int cx = static_cast<int>(std::lround(q.x)), cy = static_cast<int>(std::lround(q.y));
    const cv::Rect templ(cx - r, cy - r, 2 * r + 1, 2 * r + 1);
    const cv::Rect search(cx - r - R, cy - r - R, 2 * (r + R) + 1, 2 * (r + R) + 1);
    if ((search & bounds) != search) continue;
    if (cv::countNonZero(valid(templ)) != templ.area()) continue;
    correlatePatch(img(search), warped(templ), result);
    double best = 0;
    cv::Point loc;
    cv::minMaxLoc(result, nullptr, &best, nullptr, &loc);
    if (!(best >= params.refineMinScore)) continue;
    if (loc.x <= 0 || loc.y <= 0 || loc.x >= result.cols - 1 || loc.y >= result.rows - 1) continue;
    const CorrelationPeak peak = correlationPeak(result, loc);
    FeatureMatch m;
    m.ref = c.pt;
    m.image = {q.x + (loc.x - R) + peak.offset.x, q.y + (loc.y - R) + peak.offset.y};
    m.peakCurvature = peak.curvature;
    m.score = best;
    const cv::Matx22d J = jacobianAt(H, c.pt);
    m.rotationDeg = rotationDegOf(J);
    m.scale = std::sqrt(std::abs(cv::determinant(J)));
    out.push_back(m);
  }
  return out;
}

// How far `after` puts any of the reference's points from where `before` put them, over those
// `after` maps into an image of `size` (pixels in the image): the step of one re-matching.
double largestMove(const cv::Matx33d& before, const cv::Matx33d& after,
                   const std::vector<HarrisCorner>& points, cv::Size size) {
  double largest = 0.0;
  for (const HarrisCorner& c : points) {
    const cv::Point2d q = mapPoint(after, c.pt);
    if (!(q.x >= 0 && q.y >= 0 && q.x <= size.width - 1 && q.y <= size.height - 1)) continue;
    largest = std::max(largest, cv::norm(q - mapPoint(before, c.pt)));
  }
  return largest;
}

struct GlobalStage {
  std::vector<FeatureMatch> matches;
  std::vector<int> inliers;  // indices into matches
  cv::Matx33d H = cv::Matx33d::eye();
  std::vector<GlobalFit> runnersUp;  // other fits, inliers as indices into matches
  int refCorners = 0, imageCorners = 0;
  Status<RegistrationFailure> status;  // ok when a transform was found
};

// The windows of the corners of rank below `count`.
Features ranksBelow(const Features& f, int count) {
  Features s;
  for (std::size_t i = 0; i < f.windows.size(); ++i)
    if (f.ranks[i] < count) {
      s.regions.push_back(f.regions[i]);
      s.windows.push_back(f.windows[i]);
      s.ranks.push_back(f.ranks[i]);
    }
  return s;
}

// A global stage on the windows `a` and `b`: failed (too_few_corners) when either has fewer than
// four.
GlobalStage startGlobalStage(const Features& a, const Features& b) {
  GlobalStage g;
  g.refCorners = static_cast<int>(a.windows.size());
  g.imageCorners = static_cast<int>(b.windows.size());
  if (a.windows.size() < 4 || b.windows.size() < 4) {
    g.status.cause = RegistrationFailure::TooFewCorners;
    g.status.message = "fewer than 4 usable corners (reference " +
                       std::to_string(a.windows.size()) + ", image " +
                       std::to_string(b.windows.size()) + ")";
  }
  return g;
}

NccMatchParams windowMatching(const RegistrationParams& params, double minScore) {
  NccMatchParams mp = params.matching;
  mp.minScore = minScore;
  return mp;
}

// The global fit of window matches of `a` and `b`: pruning by the matches' own rotation/scale,
// robust fit seeded by their local maps.
GlobalStage fitWindowMatches(const Features& a, const Features& b,
                             const std::vector<WindowMatch>& wm, const RegistrationParams& params,
                             cv::Point2d refCentre) {
  GlobalStage g = startGlobalStage(a, b);
  if (!g.status.ok()) return g;
  std::vector<cv::Matx22d> maps;
  for (const WindowMatch& w : wm) {
    const AffineRegion& ra = a.regions[w.ref];
    const AffineRegion& rb = b.regions[w.image];
    const cv::Matx22d L = localMap(ra, rb, w.best, params.window);
    g.matches.push_back(
        {ra.pt, rb.pt, w.best.score, rotationDegOf(L), std::sqrt(std::abs(cv::determinant(L)))});
    maps.push_back(L);
  }
  const std::vector<int> kept =
      agreeingRotationScale(g.matches, params.pruneRotationDeg, params.pruneLog2Scale);
  std::vector<cv::Point2d> src, dst;
  std::vector<cv::Matx22d> keptMaps;
  for (int k : kept) {
    src.push_back(g.matches[k].ref);
    dst.push_back(g.matches[k].image);
    keptMaps.push_back(maps[k]);
  }
  const int minimal = params.model == TransformModel::Similarity ? 2
                      : params.model == TransformModel::Affine   ? 3
                                                                 : 4;
  const int needed = std::max(minimal, params.minInliers);
  if (static_cast<int>(src.size()) < needed) {
    g.status.cause = RegistrationFailure::TooFewMatches;
    g.status.message = std::to_string(src.size()) + " consistent matches, at least " +
                       std::to_string(needed) + " needed";
    return g;
  }
  TransformFitParams fp;
  fp.model = params.model;
  fp.inlierThreshold = params.inlierThreshold;
  std::optional<TransformFit> fit = fitTransformWithLocalMaps(src, dst, keptMaps, fp);
  std::vector<TransformFit> others;
  if (params.runnersUp > 0 &&
      (!fit || static_cast<int>(fit->inliers.size()) < params.confirmBelowInliers)) {
    // The fit needs confirming: the other consensus sets are candidates too, the most inliers
    // first, RANSAC's on a tie.
    std::vector<TransformFit> sets =
        enumerateConsensusSets(src, dst, fp, params.runnersUp + 1, params.consensusSamples);
    if (fit) sets.insert(sets.begin(), *fit);
    std::stable_sort(sets.begin(), sets.end(), [](const TransformFit& a, const TransformFit& b) {
      return a.inliers.size() > b.inliers.size();
    });
    for (TransformFit& f : sets) {
      const bool seen = std::any_of(others.begin(), others.end(),
                                    [&](const TransformFit& o) { return o.inliers == f.inliers; });
      if (!seen) others.push_back(std::move(f));
    }
    if (!others.empty()) {
      fit = std::move(others.front());
      others.erase(others.begin());
    }
  }
  if (!fit) {
    g.status.cause = RegistrationFailure::DegenerateTransform;
    g.status.message = "no non-degenerate transform fits the matches";
    return g;
  }
  if (static_cast<int>(fit->inliers.size()) < params.minInliers) {
    g.status.cause = RegistrationFailure::TooFewInliers;
    g.status.message = std::to_string(fit->inliers.size()) + " inliers, at least " +
                       std::to_string(params.minInliers) + " needed";
    return g;
  }
  // The detector sees structures over params.corners.octaves octaves: a fit that magnifies the
  // view beyond that was made of chance matches (and its re-matching would blur the image by
  // hundreds of pixels to match resolutions).
  const double reach = std::ldexp(1.0, params.corners.octaves);
  const auto withinReach = [&](const cv::Matx33d& H) {
    const double m = magnificationAt(H, refCentre);
    return m <= reach && m >= 1.0 / reach;
  };
  if (!withinReach(fit->H)) {
    const double magnification = magnificationAt(fit->H, refCentre);
    g.status.cause = RegistrationFailure::DegenerateTransform;
    g.status.message = "the fit magnifies the view " + std::to_string(magnification) +
                       " times, beyond the detector's " + std::to_string(params.corners.octaves) +
                       " octaves";
    return g;
  }
  g.H = fit->H;
  for (int i : fit->inliers) g.inliers.push_back(kept[i]);
  for (const TransformFit& f : others) {
    if (static_cast<int>(g.runnersUp.size()) >= params.runnersUp ||
        static_cast<int>(f.inliers.size()) < params.minInliers || !withinReach(f.H))
      continue;
    GlobalFit runnerUp{f.H, {}};
    for (int i : f.inliers) runnerUp.inliers.push_back(kept[i]);
    g.runnersUp.push_back(std::move(runnerUp));
  }
  return g;
}

// All-pairs window matching of the first `count` corners of each image, then the global fit.
GlobalStage matchGlobally(const Features& fr, const Features& fi, int count, double minScore,
                          const RegistrationParams& params, cv::Point2d refCentre) {
  const Features a = ranksBelow(fr, count), b = ranksBelow(fi, count);
  const GlobalStage start = startGlobalStage(a, b);
  if (!start.status.ok()) return start;
  const std::vector<WindowMatch> wm = matchWindows(a.windows, b.windows, params.window.ringShifts,
                                                   windowMatching(params, minScore));
  return fitWindowMatches(a, b, wm, params, refCentre);
}

void takeGlobalStage(const GlobalStage& stage, RegistrationResult& result) {
  result.refCorners = stage.refCorners;
  result.imageCorners = stage.imageCorners;
  result.matches = stage.matches;
  if (!stage.status.ok()) {
    result.status = stage.status;
    return;
  }
  result.H = stage.H;
  result.inliers = stage.inliers;
  result.globalInliers = static_cast<int>(result.inliers.size());
  result.runnersUp = stage.runnersUp;
}

}  // namespace

std::vector<cv::Vec4d> RegistrationResult::pairs() const {
  std::vector<cv::Vec4d> out;
  for (int i : inliers)
    out.emplace_back(matches[i].ref.x, matches[i].ref.y, matches[i].image.x, matches[i].image.y);
  return out;
}

struct StageCache::State {
  Status<RegistrationFailure> status;  // failed: an empty or uniform image
  cv::Mat ref, img;                    // grey on [0, 1]
  std::vector<cv::Mat> refPyramid, imgPyramid;
  // Detected once with the larger budget: the corners come in spreading order, so the first
  // maxCorners of them are what a smaller budget would have kept.
  std::vector<HarrisCorner> refCorners, imgCorners;
  // Per detector (plain, affine): the windows described so far and the first global match.
  struct Detector {
    Features ref, img;
    std::optional<GlobalStage> first;
    // The look-alike stage's window matches (plain windows, each reference window's best few),
    // kept for the plain escalation, which takes the best of each from them.
    std::optional<std::vector<WindowMatch>> lookalikes;
  };
  Detector plain, affine;
  std::optional<std::vector<HarrisCorner>> grid;  // reference points for the re-matching
  int gridCell = 0;                               // the grid's cell, reference pixels
};

StageCache::StageCache(const cv::Mat& refImage, const cv::Mat& image,
                       const RegistrationParams& params)
    : state(std::make_unique<State>()) {
  State& s = *state;
  if (refImage.empty() || image.empty()) {
    s.status = Status<RegistrationFailure>::failed(
        RegistrationFailure::EmptyImage,
        refImage.empty() ? "the reference image is empty" : "the image is empty");
    return;
  }
  s.ref = unitGrey(refImage);
  s.img = unitGrey(image);
  if (isBlank(s.ref)) {
    s.status = Status<RegistrationFailure>::failed(
        RegistrationFailure::BlankImage, "the reference image is uniform: no corners to register");
    return;
  }
  if (isBlank(s.img)) {
    s.status = Status<RegistrationFailure>::failed(RegistrationFailure::BlankImage,
                                                   "the image is uniform: no corners to register");
    return;
  }
  s.refPyramid = buildSamplingPyramid(s.ref);
  s.imgPyramid = buildSamplingPyramid(s.img);
  HarrisParams hp = params.corners;
  hp.maxCorners = std::max(params.corners.maxCorners, params.escalateCorners);
  s.refCorners = detectHarrisCorners(s.ref, hp);
  s.imgCorners = detectHarrisCorners(s.img, hp);
}

StageCache::~StageCache() = default;

RegistrationResult registerSingleStage(const cv::Mat& refImage, const cv::Mat& image,
                                       const RegistrationParams& params) {
  StageCache cache(refImage, image, params);
  return registerStage(cache, params, true);
}

RegistrationResult registerStage(StageCache& cache, const RegistrationParams& params, bool widen) {
  RegistrationResult result = matchStage(cache, params, widen);
  if (result.status.ok()) refineStage(cache, params, result);
  return result;
}

RegistrationResult matchStage(StageCache& cache, const RegistrationParams& params, bool widen) {
  RegistrationResult result;
  result.stage = params.affineRegions ? "harris-affine" : "harris";
  StageCache::State& s = *cache.state;
  if (!s.status.ok()) {
    result.status = s.status;
    return result;
  }
  StageCache::State::Detector& d = params.affineRegions ? s.affine : s.plain;
  if (!d.first) {
    describeUpTo(d.ref, s.refCorners, s.refPyramid, params, params.corners.maxCorners);
    describeUpTo(d.img, s.imgCorners, s.imgPyramid, params, params.corners.maxCorners);
    d.first = matchGlobally(d.ref, d.img, params.corners.maxCorners, params.matching.minScore,
                            params, centreOf(s.ref));
  }
  // The first stage stays in the cache (the other detector's run or a later call reuses it); the
  // result copies from whichever stage is kept.
  const GlobalStage* stage = &*d.first;
  GlobalStage wider;
  if (widen && params.escalateCorners > params.corners.maxCorners &&
      static_cast<int>(stage->inliers.size()) < params.escalateBelowInliers) {
    describeUpTo(d.ref, s.refCorners, s.refPyramid, params, params.escalateCorners);
    describeUpTo(d.img, s.imgCorners, s.imgPyramid, params, params.escalateCorners);
    // The look-alike stage, where it ran first, has matched the same windows at the same minimum
    // score (registration_stages.cpp).
    if (d.lookalikes && params.matching.candidates <= 1)
      wider = fitWindowMatches(ranksBelow(d.ref, params.escalateCorners),
                               ranksBelow(d.img, params.escalateCorners), bestOfEach(*d.lookalikes),
                               params, centreOf(s.ref));
    else
      wider = matchGlobally(d.ref, d.img, params.escalateCorners, params.escalateMinScore, params,
                            centreOf(s.ref));
    if (wider.inliers.size() > stage->inliers.size() || (!stage->status.ok() && wider.status.ok()))
      stage = &wider;
  }
  takeGlobalStage(*stage, result);
  return result;
}

RegistrationResult matchLookalikes(StageCache& cache, const RegistrationParams& params) {
  RegistrationResult result;
  result.stage = "harris-lookalikes";
  StageCache::State& s = *cache.state;
  if (!s.status.ok()) {
    result.status = s.status;
    return result;
  }
  RegistrationParams lookalikes = params;
  lookalikes.affineRegions = false;
  lookalikes.matching.candidates = std::max(1, params.lookalikeCandidates);
  const int count = std::max(params.corners.maxCorners, params.escalateCorners);
  StageCache::State::Detector& d = s.plain;
  describeUpTo(d.ref, s.refCorners, s.refPyramid, lookalikes, count);
  describeUpTo(d.img, s.imgCorners, s.imgPyramid, lookalikes, count);
  const Features a = ranksBelow(d.ref, count), b = ranksBelow(d.img, count);
  GlobalStage stage = startGlobalStage(a, b);
  if (stage.status.ok()) {
    if (!d.lookalikes)
      d.lookalikes = matchWindows(a.windows, b.windows, params.window.ringShifts,
                                  windowMatching(lookalikes, params.escalateMinScore));
    stage = fitWindowMatches(a, b, *d.lookalikes, lookalikes, centreOf(s.ref));
  }
  takeGlobalStage(stage, result);
  return result;
}

namespace {

// The grid points that H puts inside the image: the pairs a re-matching around H could find.
std::size_t gridPointsSeen(const std::vector<HarrisCorner>& grid, const cv::Matx33d& H,
                           cv::Size image) {
  std::size_t seen = 0;
  for (const HarrisCorner& c : grid) {
    const cv::Point2d q = mapPoint(H, c.pt);
    seen += q.x >= 0 && q.y >= 0 && q.x <= image.width - 1 && q.y <= image.height - 1;
  }
  return seen;
}

// The warp-and-re-match of one global fit, then its confirmation (refineStage).
void rematchFit(StageCache& cache, const RegistrationParams& params, RegistrationResult& result) {
  StageCache::State& s = *cache.state;
  const auto globalInliers = static_cast<std::size_t>(result.globalInliers);
  if (params.refineIterations > 0) {
    TransformFitParams tight;
    tight.model = params.model;
    tight.inlierThreshold = params.finalThreshold;
    // The grid's cell is refineCell pixels of the finer view: where the image magnifies the
    // reference, a cell of the reference holds s^2 times more image pixels, each able to match.
    const double magnification = magnificationAt(result.H, centreOf(s.ref));
    const int cell =
        magnification > 1.0
            ? std::max(1, static_cast<int>(std::lround(params.refineCell / magnification)))
            : params.refineCell;
    if (!s.grid || s.gridCell != cell) {
      s.grid = detectHarrisGrid(s.ref, cell, params.corners);
      s.gridCell = cell;
    }
    const std::vector<HarrisCorner>& dense = *s.grid;
    std::size_t rematched = 0;  // pairs the last accepted re-matching found
    RematchViews views;
    for (int it = 0; it < params.refineIterations; ++it) {
      // Once H rests on the dense pairs, the prediction is within a pixel or two.
      const int radius =
          it == 0 ? params.refineSearchRadius : std::min(params.refineSearchRadius, 3);
      std::vector<FeatureMatch> rm = rematch(s.ref, s.img, dense, result.H, radius, params, views);
      std::vector<cv::Point2d> s2, d2;
      for (const auto& m : rm) {
        s2.push_back(m.ref);
        d2.push_back(m.image);
      }
      // The re-matched pairs are subpixel: the consensus is sought at the tight threshold so that
      // a cluster of slightly wrong pairs cannot bias H; inliers are then counted as usual.
      const auto refit = fitTransformRobust(s2, d2, tight);
      if (!refit) break;
      std::vector<int> inliers;
      for (std::size_t i = 0; i < s2.size(); ++i)
        if (transferError(refit->H, s2[i], d2[i]) <= params.inlierThreshold)
          inliers.push_back(static_cast<int>(i));
      if (inliers.size() < result.inliers.size()) break;
      const double moved = largestMove(result.H, refit->H, dense, s.img.size());
      result.H = refit->H;
      rematched = rm.size();
      result.matches = std::move(rm);
      result.inliers = std::move(inliers);
      ++result.refinePasses;
      result.refineLastMove = moved;
      if (moved <= params.refineConvergence) break;
    }
    result.defocus = views.defocus.value_or(0.0);
    // A transform resting on very few global matches must be confirmed by the re-matching: at
    // least confirmInliers pairs, most of those it found, and a share of the grid points it
    // puts in the image. Around the right transform most grid points re-match and nearly every
    // re-matched pair agrees with it; around a wrong one the pairs are chance hits of the
    // correlation (a fine repetitive texture gives many), of which one homography explains a
    // few dozen among a hundred and more, out of the thousands of grid points it was tried at.
    // Only pairs the re-matching found confirm: where it found none, the inliers are still the
    // global ones it was to confirm.
    if (static_cast<int>(globalInliers) >= params.confirmBelowInliers) return;
    const std::size_t confirmed = rematched > 0 ? result.inliers.size() : 0;
    const double seen = static_cast<double>(gridPointsSeen(dense, result.H, s.img.size()));
    if (static_cast<int>(confirmed) < params.confirmInliers || 2 * confirmed < rematched ||
        static_cast<double>(confirmed) < params.confirmSeenShare * seen)
      result.status = Status<RegistrationFailure>::failed(
          RegistrationFailure::TooFewInliers,
          std::to_string(globalInliers) + " global inliers, not confirmed by re-matching (" +
              (rematched > 0 ? std::to_string(confirmed) + " inliers of " +
                                   std::to_string(rematched) + " re-matched pairs; "
                             : "no re-matched fit; ") +
              std::to_string(params.confirmInliers) + " inliers, most pairs and " +
              std::to_string(static_cast<int>(std::lround(100 * params.confirmSeenShare))) +
              " % of the " + std::to_string(static_cast<long>(seen)) +
              " grid points it puts in the image needed)");
  }
}

}  // namespace

void refineStage(StageCache& cache, const RegistrationParams& params, RegistrationResult& result) {
  if (params.refineIterations <= 0 || result.runnersUp.empty()) {
    rematchFit(cache, params, result);
    return;
  }
  // A fit that needs confirming and is not confirmed gives way to the first runner-up that is.
  // Around a wrong fit the re-matching finds few pairs and stops after a pass or two. Each fit
  // tried is one more chance for chance pairs to pass for a confirmation (a fine or repeated
  // texture gives many: baboon.jpg magnified 3 times, a wrong runner-up confirmed by 48 of 58
  // pairs; sudoku.png magnified 3 times, a wrong best fit by 38 of 64), so a confirmed fit must
  // also re-match a share of the grid points it puts in the image (confirmSeenShare): the true
  // fit on graf 1-6 re-matches 1196 of 1565, those wrong ones 48 of 17118 and 38 of over 152.
  const RegistrationResult global = result;
  rematchFit(cache, params, result);
  for (std::size_t k = 0; k < global.runnersUp.size() && !result.status.ok(); ++k) {
    const GlobalFit& other = global.runnersUp[k];
    RegistrationResult candidate = global;
    candidate.H = other.H;
    candidate.inliers = other.inliers;
    candidate.globalInliers = static_cast<int>(other.inliers.size());
    candidate.consensusRank = static_cast<int>(k) + 1;
    rematchFit(cache, params, candidate);
    if (candidate.status.ok()) result = std::move(candidate);
  }
  if (!result.status.ok() && result.status.cause == RegistrationFailure::TooFewInliers)
    result.status.message += "; nor was any of the " + std::to_string(global.runnersUp.size()) +
                             " other consensus sets of the window matches";
}

}  // namespace facet
