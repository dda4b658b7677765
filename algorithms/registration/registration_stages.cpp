// The default registration pipeline: the fast plain-Harris stage first, Harris-Affine regions
// when that finds no transform it can stand on. Why not always Harris-Affine: its shape
// adaptation costs several times the plain windows, and most pairs (small viewpoint changes,
// rotation, zoom) do not need it; why not plain Harris alone: beyond about 30 degrees of
// viewpoint change its windows no longer match, and the few chance matches left can still agree
// on a wrong transform.
#include "algorithms/registration/register_images.hpp"

#include <limits>
#include <optional>
#include <vector>

#include "algorithms/registration/robust_homography.hpp"

namespace facet {
namespace {

// The last step for a homography: the re-matched pairs within inlierThreshold of H, fitted by
// the Cauchy loss of their transfer errors at their own noise scale (robust_homography.cpp says
// why not least squares within a fixed distance). The RANSAC before it minimises an algebraic
// error over the pairs within finalThreshold, which weights them unevenly across the image
// and, on a real lens, keeps only the part of the view that fits best.
void polishHomography(RegistrationResult& r, const RegistrationParams& params) {
  // Each pair counts by how sharply its correlation peak locates it in each direction, as far
  // as that and not an error all pairs share limits it (robust_homography.cpp); a pair whose
  // surface is no peak (a ridge, a plateau) is left out.
  std::vector<cv::Point2d> src, dst;
  std::vector<cv::Matx22d> sharpness;
  for (const FeatureMatch& m : r.matches)
    if (transferError(r.H, m.ref, m.image) <= params.inlierThreshold &&
        cv::determinant(m.peakCurvature) > 0) {
      src.push_back(m.ref);
      dst.push_back(m.image);
      sharpness.push_back(m.peakCurvature);
    }
  const std::optional<RobustHomography> fit = fitHomographyCauchy(src, dst, r.H, sharpness);
  if (!fit) return;
  std::vector<int> inliers;
  for (std::size_t i = 0; i < r.matches.size(); ++i)
    if (transferError(fit->H, r.matches[i].ref, r.matches[i].image) <= params.inlierThreshold)
      inliers.push_back(static_cast<int>(i));
  // A few pairs near the inlier threshold cross it whenever H moves; a polish that loses more
  // than that has been drawn off by wrong pairs and is not kept.
  if (inliers.size() + r.inliers.size() / 100 < r.inliers.size()) return;
  r.H = fit->H;
  r.inliers = std::move(inliers);
}

// Re-matches a global result; true when it is then a registration (confirmed when it must be).
bool refined(StageCache& cache, const RegistrationParams& params, RegistrationResult& r) {
  if (!r.status.ok()) return false;
  refineStage(cache, params, r);
  return r.status.ok();
}

RegistrationResult registerStages(const cv::Mat& ref, const cv::Mat& image,
                                  const RegistrationParams& params) {
  StageCache cache(ref, image, params);
  if (params.affineRegions || !params.escalateToAffine) return registerStage(cache, params, true);
  // The plain stage's own escalation to escalateCorners is deferred. It runs when the first match
  // has fewer than escalateBelowInliers inliers, and then the affine stage follows unless the
  // wider match reaches affineBelowInliers, which it seldom does from there; the affine stage
  // (which escalates in turn) costs about as much and is what such a pair needs.
  RegistrationResult fast = matchStage(cache, params, false);
  if (fast.status.ok() && fast.globalInliers >= params.affineBelowInliers &&
      refined(cache, params, fast))
    return fast;
  const bool fastRefined = fast.status.ok() && fast.globalInliers >= params.affineBelowInliers;
  RegistrationParams affine = params;
  affine.affineRegions = true;
  RegistrationResult adapted = matchStage(cache, affine, true);
  adapted.escalated = fast.escalated = true;
  // The result with more global inliers is kept (the plain one on a tie) if its re-matching
  // confirms it, else the other one if its own does: only the kept one is re-matched, which
  // saves the re-matching of the plain stage whenever the affine one wins.
  const bool affineFirst =
      adapted.status.ok() && (!fast.status.ok() || adapted.globalInliers > fast.globalInliers);
  if (affineFirst && refined(cache, affine, adapted)) return adapted;
  if (fast.status.ok() && (fastRefined || refined(cache, params, fast))) return fast;
  if (!affineFirst && refined(cache, affine, adapted)) return adapted;
  // Neither stage found a transform: the deferred plain escalation is the last resort (not when
  // it would repeat the plain stage: no wider budget, or a first match that needs none).
  if (params.escalateCorners > params.corners.maxCorners &&
      fast.globalInliers < params.escalateBelowInliers) {
    RegistrationResult wider = registerStage(cache, params, true);
    wider.escalated = true;
    if (wider.status.ok()) return wider;
  }
  // Nor that: a repeated pattern, where a window's true partner need not be its best match. A fit
  // chosen among look-alikes is kept only when the re-matching confirms it, however many global
  // inliers it has.
  if (params.lookalikeCandidates > 1) {
    RegistrationParams lookalikes = params;
    lookalikes.confirmBelowInliers = std::numeric_limits<int>::max();
    RegistrationResult repeated = matchLookalikes(cache, lookalikes);
    repeated.escalated = true;
    if (refined(cache, lookalikes, repeated)) return repeated;
  }
  return adapted;
}

}  // namespace

RegistrationResult registerImages(const cv::Mat& ref, const cv::Mat& image,
                                  const RegistrationParams& params) {
  RegistrationResult r = registerStages(ref, image, params);
  if (r.status.ok() && params.model == TransformModel::Homography && params.refineIterations > 0 &&
      params.polishHomography)
    polishHomography(r, params);
  return r;
}

}  // namespace facet
