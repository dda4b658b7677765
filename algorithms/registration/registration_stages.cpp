// The default registration pipeline: the fast plain-Harris stage first, Harris-Affine regions
// when that finds no transform it can stand on. Why not always Harris-Affine: its shape
// adaptation costs several times the plain windows, and most pairs (small viewpoint changes,
// rotation, zoom) do not need it; why not plain Harris alone: beyond about 30 degrees of
// viewpoint change its windows no longer match, and the few chance matches left can still agree
// on a wrong transform.
#include "algorithms/registration/register_images.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <optional>
#include <sstream>
#include <vector>

#include <opencv2/imgproc.hpp>

#include "algorithms/registration/homography_uncertainty.hpp"
#include "algorithms/registration/robust_homography.hpp"
#include "algorithms/registration/transform_fit.hpp"

namespace facet {
namespace {

// The corners of the part of the reference that the image sees: the reference's rectangle cut
// by the image's, carried back through H. The reference's corners where that is no convex
// quadrilateral (a horizon crosses the image).
std::vector<cv::Point2d> overlapCorners(const cv::Matx33d& H, cv::Size ref, cv::Size image) {
  const auto corners = [](cv::Size s) {
    const float w = static_cast<float>(s.width - 1), h = static_cast<float>(s.height - 1);
    return std::vector<cv::Point2f>{{0, 0}, {w, 0}, {w, h}, {0, h}};
  };
  const std::vector<cv::Point2f> refCorners = corners(ref);
  std::vector<cv::Point2d> fallback(refCorners.begin(), refCorners.end());
  std::vector<cv::Point2f> seen;
  for (const cv::Point2f& q : corners(image)) {
    const cv::Point2d p = mapPoint(H.inv(), cv::Point2d(q));
    if (!std::isfinite(p.x) || !std::isfinite(p.y)) return fallback;
    seen.emplace_back(static_cast<float>(p.x), static_cast<float>(p.y));
  }
  if (!cv::isContourConvex(seen)) return fallback;
  std::vector<cv::Point2f> overlap;
  if (cv::intersectConvexConvex(refCorners, seen, overlap) <= 0) return fallback;
  return {overlap.begin(), overlap.end()};
}

std::vector<cv::Point2d> residualsOf(const cv::Matx33d& H, const std::vector<cv::Point2d>& src,
                                     const std::vector<cv::Point2d>& dst) {
  std::vector<cv::Point2d> r;
  for (std::size_t i = 0; i < src.size(); ++i) r.push_back(mapPoint(H, src[i]) - dst[i]);
  return r;
}

// Re-matched pairs closer than a patch's width share pixels, and so their errors.
double patchDiameter(const RegistrationParams& params) {
  return 2.0 * params.refinePatchRadius + 1.0;
}

// The last step for a homography: the re-matched pairs within inlierThreshold of H, fitted by
// the Cauchy loss of their transfer errors at their own noise scale (robust_homography.cpp says
// why not least squares within a fixed distance). The RANSAC before it minimises an algebraic
// error over the pairs within finalThreshold, which weights them unevenly across the image
// and, on a real lens, keeps only the part of the view that fits best.
// Its result's overlapUncertainty is propagated from each pair's error as the fit modelled it.
void polishHomography(RegistrationResult& r, const RegistrationParams& params, cv::Size ref,
                      cv::Size image) {
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
  std::vector<cv::Matx22d> covariance = fit->errorCovariance;
  const double shared = sharedErrorFactor(src, residualsOf(r.H, src, dst), patchDiameter(params));
  for (cv::Matx22d& c : covariance) c *= shared;
  r.overlapUncertainty = mappedPointUncertainty(TransformModel::Homography, r.H, src, dst,
                                                covariance, overlapCorners(r.H, ref, image));
}

// How far the result's H may put the overlap's points, from its inliers' spread and noise, for a
// result the Cauchy fit did not polish. The noise is the inliers' own: the median transfer error
// of a 2D Gaussian is its sigma times sqrt(2 ln 2).
double overlapUncertaintyOf(const RegistrationResult& r, const RegistrationParams& params,
                            cv::Size ref, cv::Size image) {
  std::vector<cv::Point2d> src, dst;
  for (int i : r.inliers) {
    src.push_back(r.matches[i].ref);
    dst.push_back(r.matches[i].image);
  }
  if (src.empty()) return std::numeric_limits<double>::infinity();
  const std::vector<cv::Point2d> residuals = residualsOf(r.H, src, dst);
  std::vector<double> errors;
  for (const cv::Point2d& e : residuals) errors.push_back(std::hypot(e.x, e.y));
  std::nth_element(errors.begin(), errors.begin() + errors.size() / 2, errors.end());
  const double shared = sharedErrorFactor(src, residuals, patchDiameter(params));
  const double noise = std::sqrt(shared) * errors[errors.size() / 2] / std::sqrt(2 * std::log(2.0));
  return mappedPointUncertainty(params.model, r.H, src, dst, noise,
                                overlapCorners(r.H, ref, image));
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
  // Neither stage found a transform: the deferred plain escalation is the last resort but one
  // (not when it would repeat the plain stage: no wider budget, or a first match that needs none),
  // then look-alikes: a repeated pattern, where a window's true partner need not be its best
  // match. Both match the plain windows within the wider budget at the same minimum score, so the
  // look-alike matching (each window's best few) runs first and the escalation takes the best of
  // each from it (ncc_matcher.hpp, bestOfEach): one all-pairs pass instead of two, the same
  // matches. A fit chosen among look-alikes is kept only when the re-matching confirms it,
  // however many global inliers it has.
  RegistrationParams lookalikes = params;
  lookalikes.confirmBelowInliers = std::numeric_limits<int>::max();
  std::optional<RegistrationResult> repeated;
  if (params.lookalikeCandidates > 1) repeated = matchLookalikes(cache, lookalikes);
  if (params.escalateCorners > params.corners.maxCorners &&
      fast.globalInliers < params.escalateBelowInliers) {
    RegistrationResult wider = registerStage(cache, params, true);
    wider.escalated = true;
    if (wider.status.ok()) return wider;
  }
  if (repeated) {
    repeated->escalated = true;
    if (refined(cache, lookalikes, *repeated)) return *std::move(repeated);
  }
  return adapted;
}

}  // namespace

RegistrationResult registerImages(const cv::Mat& ref, const cv::Mat& image,
                                  const RegistrationParams& params) {
  RegistrationResult r = registerStages(ref, image, params);
  if (r.status.ok() && params.model == TransformModel::Homography && params.refineIterations > 0 &&
      params.polishHomography)
    polishHomography(r, params, ref.size(), image.size());
  if (!r.status.ok()) return r;
  // A result is claimed within inlierThreshold wherever the two views overlap: the 95 % ellipse
  // of each of the overlap's corners (2.45 sigma in 2D) must lie within it.
  if (std::isinf(r.overlapUncertainty))
    r.overlapUncertainty = overlapUncertaintyOf(r, params, ref.size(), image.size());
  constexpr double k95 = 2.4477;  // sqrt of the chi-square quantile 0.95 with 2 degrees of freedom
  if (!(k95 * r.overlapUncertainty <= params.inlierThreshold)) {
    std::ostringstream why;
    why << "the " << r.inliers.size()
        << " inliers fix the transform only near them: the corners of the views' overlap are "
           "uncertain by "
        << r.overlapUncertainty << " px (1 sigma; at most " << params.inlierThreshold / k95
        << " px for their 95 % ellipse within the inlier threshold of " << params.inlierThreshold
        << " px)";
    r.status =
        Status<RegistrationFailure>::failed(RegistrationFailure::UndeterminedTransform, why.str());
  }
  return r;
}

}  // namespace facet
