#pragma once
// Feature-based registration of an image to a reference (seed dissertation, part 3):
// Harris corners (or Harris-Affine regions) -> log-polar windows -> NCC matching over cyclic
// angle shifts and log-radius shifts -> robust fit (RANSAC, then least squares on the inliers)
// -> optionally warp the reference with the estimate and re-match around the prediction.
//
// The result H maps reference pixel coordinates to image pixel coordinates (homogeneous,
// x right, y down, pixel centres at integers): q ~ H * (x, y, 1).

#include <limits>
#include <memory>
#include <string>
#include <vector>

#include <opencv2/core.hpp>

#include "algorithms/geometry/projective_map.hpp"  // mapPoint: a reference point through H
#include "algorithms/registration/harris_corners.hpp"
#include "algorithms/registration/log_polar_window.hpp"
#include "algorithms/registration/ncc_matcher.hpp"
#include "algorithms/registration/registration_failure.hpp"
#include "algorithms/registration/transform_fit.hpp"
#include "algorithms/status/status.hpp"

namespace facet {

struct RegistrationParams {
  TransformModel model = TransformModel::Homography;  // family of H that is fitted
  // Harris-Affine regions (scale selection + affine shape adaptation) instead of plain
  // multi-scale Harris corners: slower, needed for large viewpoint changes (> ~30 degrees).
  bool affineRegions = false;
  HarrisParams corners;          // detection of the points that are matched globally
  LogPolarParams window;         // log-polar window sampled around each point
  NccMatchParams matching;       // minimum NCC, shift ranges and the three accelerations
  double inlierThreshold = 3.0;  // pixels; RANSAC reprojection threshold in the image
  int minInliers = 5;            // fewer global inliers than this -> failure "too_few_inliers"
  // A global fit with fewer than `confirmBelowInliers` inliers is accepted only when the
  // re-matching (refineIterations > 0) then finds at least `confirmInliers` inliers, they are
  // most of the pairs it re-matched, and at least `confirmSeenShare` of the re-matching's grid
  // points that the fit puts in the image (refineStage, register_images.cpp, says why).
  int confirmBelowInliers = 10;
  int confirmInliers = 20;
  double confirmSeenShare = 0.25;
  // Such a fit may be one of several the window matches support about as well (a 60 degree
  // viewpoint change leaves 5-8 true matches among 40-400, and chance ones agree as often): the
  // distinct consensus sets of at most 64 pruned matches are enumerated (transform_fit.hpp,
  // up to `consensusSamples` minimal samples), and up to `runnersUp` of them besides the best
  // are re-matched in turn when the best one is not confirmed. 0 disables it.
  int runnersUp = 8;
  long consensusSamples = 200000;
  // Per-match rotation/scale estimates prune matches that disagree with the dominant pair of
  // rotation (degrees) and log2-scale before RANSAC (rotation_scale_vote.hpp). <= 0 disables
  // the pruning.
  double pruneRotationDeg = 40.0;
  double pruneLog2Scale = 1.0;
  // Escalation for hard pairs (large viewpoint change): when the first global matching gives
  // fewer than `escalateBelowInliers` inliers, it is repeated with `escalateCorners` corners per
  // image and the minimum NCC lowered to `escalateMinScore`. escalateCorners <= maxCorners
  // disables it. registerImages defers it in the plain stage when escalateToAffine is on (the
  // affine stage comes first, this one only if neither finds a transform).
  int escalateCorners = 650;
  double escalateMinScore = 0.7;
  int escalateBelowInliers = 12;
  // Iterative refinement: warp the reference with the current H, re-match Harris points spread
  // on a grid (the strongest per `refineCell` x `refineCell` block) around their predicted
  // positions (NCC of square patches within `refineSearchRadius` pixels), refit; repeated until
  // the refit moves no grid point the image sees by more than `refineConvergence` pixels, at
  // most `refineIterations` times. A pair is biased towards the H its patch was warped with (the
  // patch is turned and scaled by H's error, and its peak follows the patch's off-centre
  // detail), so each pass removes only part of the error: about half on a strip of text or a
  // narrow overlap, where two passes left 1.4 px at the overlap's edge and ten 0.16 px.
  // refineIterations 0 disables the refinement.
  int refineIterations = 10;
  double refineConvergence = 0.02;  // pixels in the image
  int refineCell = 10;          // pixels of the finer view (the reference, or a magnified image)
  int refineSearchRadius = 8;   // pixels, in the image (3 after the first iteration)
  int refinePatchRadius = 7;    // pixels; patches are (2r+1)^2
  double finalThreshold = 1.0;  // pixels; RANSAC threshold of the fit to the re-matched pairs
  double refineMinScore = 0.8;  // minimum NCC of a re-matched patch
  // The re-matching blurs the sharper of the two views to the other's detail first (a blurred
  // or refocused shot; relative_defocus.hpp). false: they are compared as they are.
  bool matchDefocus = true;
  // Escalation to Harris-Affine regions (registerImages only, when affineRegions is off): when
  // the plain Harris stage fails, or its global fit rests on fewer than `affineBelowInliers`
  // inliers (a large viewpoint change leaves plain windows few true matches, and a transform on
  // so few can be wrong), the pair is registered again with affine regions and the result with
  // more global inliers is kept. false = plain Harris only.
  bool escalateToAffine = true;
  int affineBelowInliers = 20;
  // The last resort of registerImages when no stage found a transform: the plain windows (the
  // escalation's budget and minimum NCC) matched again keeping the best `lookalikeCandidates`
  // image windows of every reference window, not just the best one (on a repeated pattern the
  // true partner is often not the best scoring of its look-alikes), the consensus choosing among
  // them; the result must then be confirmed by the re-matching however many global inliers it
  // has. <= 1: no such stage.
  int lookalikeCandidates = 3;
  // Last step of registerImages for a homography after the re-matching: the re-matched pairs
  // within inlierThreshold fitted by the Cauchy loss of their transfer errors at their own noise
  // scale (robust_homography.hpp, registration_stages.cpp).
  bool polishHomography = true;
};

// One correspondence between the reference and the image.
struct FeatureMatch {
  cv::Point2d ref;         // pixel in the reference
  cv::Point2d image;       // pixel in the image
  double score = 0;        // NCC in [-1, 1]
  double rotationDeg = 0;  // rotation ref -> image estimated by this match alone (degrees)
  double scale = 1;        // scale ref -> image estimated by this match alone
  // Re-matched pairs: minus the Hessian of the NCC surface at its peak (per image pixel^2), how
  // sharply the pair is located in each direction; zero for the other matches.
  cv::Matx22d peakCurvature = cv::Matx22d::zeros();
};

// A global fit of the window matches: H and its inliers (indices into the matches).
struct GlobalFit {
  cv::Matx33d H = cv::Matx33d::eye();
  std::vector<int> inliers;
};

struct RegistrationResult {
  Status<RegistrationFailure> status;
  cv::Matx33d H = cv::Matx33d::eye();  // reference -> image, H(2,2) == 1
  std::vector<FeatureMatch> matches;   // final putative matches
  std::vector<int> inliers;            // indices into `matches` consistent with H
  int refCorners = 0;                  // points detected in the reference / image
  int imageCorners = 0;
  int globalInliers = 0;  // inliers of the global (feature) fit, before the re-matching
  // The global fit's runners-up (RegistrationParams::runnersUp), tried when it is not confirmed,
  // and which of the fits this result rests on: 0 the best, k its k-th runner-up.
  std::vector<GlobalFit> runnersUp;
  int consensusRank = 0;
  // The stage whose result this is: "harris" (plain multi-scale Harris windows),
  // "harris-affine" (Harris-Affine regions) or "harris-lookalikes" (the plain windows' best few
  // partners each, the last resort); `escalated` when more than one ran (the plain one first).
  std::string stage;
  bool escalated = false;
  // How much more blurred the image is than the reference beyond what their scales explain, as
  // the re-matching found it (Gaussian sigma, image pixels; relative_defocus.hpp): negative where
  // the reference is the blurrier, 0 where the two hold the same detail or no re-matching ran.
  double defocus = 0.0;
  // The warp-and-re-match passes whose refit was kept, and how far the last of them moved H
  // (pixels, at the grid points the image sees): at most refineConvergence when the passes
  // settled, more when they stopped at refineIterations or at a refit with fewer inliers.
  int refinePasses = 0;
  double refineLastMove = 0.0;
  // How far H may put the points of the reference that the image sees (pixels, 1 sigma, at the
  // worst corner of the overlap, along its worst direction): the inliers' noise propagated
  // through the fit (homography_uncertainty.hpp). Small where the inliers spread over the
  // overlap; large where they lie on a strip or in a corner of it, when H is right only near
  // them: registerImages then fails with undetermined_transform (when 2.45 times this, the 95 %
  // ellipse, exceeds inlierThreshold), H and the matches kept for a look. Set by
  // registerImages; infinity when it found no transform.
  double overlapUncertainty = std::numeric_limits<double>::infinity();
  // Inlier correspondences as (x_ref, y_ref, x_img, y_img).
  [[nodiscard]] std::vector<cv::Vec4d> pairs() const;
};

// Registers `image` to `ref` (8-bit or 16-bit, 1 or 3 channels; converted to grey), escalating
// to Harris-Affine regions as RegistrationParams::escalateToAffine says (registration_stages.cpp).
RegistrationResult registerImages(const cv::Mat& ref, const cv::Mat& image,
                                  const RegistrationParams& params = {});
// One stage only: the detector that params.affineRegions names, no escalation between them.
RegistrationResult registerSingleStage(const cv::Mat& ref, const cv::Mat& image,
                                       const RegistrationParams& params = {});

// What the stages of one pair share, computed once: the grey images, their sampling pyramids and
// corners (detected with the larger of the two budgets), each detector's windows described so far
// and its first global match, and the reference's grid points for the re-matching. Built for
// `params`; the stages run on it may differ from them in affineRegions only.
class StageCache {
 public:
  StageCache(const cv::Mat& ref, const cv::Mat& image, const RegistrationParams& params);
  ~StageCache();
  StageCache(const StageCache&) = delete;
  StageCache& operator=(const StageCache&) = delete;
  struct State;  // register_images.cpp
  std::unique_ptr<State> state;
};

// One stage on the cache's pair: registerSingleStage, except that with `widen` false the
// escalation to escalateCorners is left out (registerImages defers the plain stage's one).
// It is matchStage, then refineStage when the global fit succeeded.
RegistrationResult registerStage(StageCache& cache, const RegistrationParams& params, bool widen);
// The global part of a stage: windows, all-pairs matching, robust fit (status, H, the window
// matches and their inliers, globalInliers).
RegistrationResult matchStage(StageCache& cache, const RegistrationParams& params, bool widen);
// The global part of the look-alike stage (lookalikeCandidates): plain windows up to
// escalateCorners, each reference window's best lookalikeCandidates image windows.
RegistrationResult matchLookalikes(StageCache& cache, const RegistrationParams& params);
// The warp-and-re-match of a global result (refineIterations), then the confirmation of a fit on
// fewer than confirmBelowInliers inliers, which may turn the result into a failure.
void refineStage(StageCache& cache, const RegistrationParams& params, RegistrationResult& result);

}  // namespace facet
