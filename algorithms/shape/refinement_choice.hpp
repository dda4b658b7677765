#pragma once
// Which pose a match keeps (internal to facet_shape): the interpolated start or its least-squares
// refinement. Two measures judge them: the score (share of the model seen with a matching
// gradient) and the support (how many of the model's subpixel points lie on image edges,
// least_squares_refinement.hpp).

namespace facet::shape_detail {

struct RefinementOutcome {
  double startScore = 0.0;
  double refinedScore = 0.0;
  double startSupport = 0.0;
  double refinedSupport = 0.0;
  // The refinement fitted everything the part may change: its scale too, within the tolerance,
  // or, where the free scale went beyond it, a refit at the start's scale that lays at least as
  // many points on edges (the scale was pulled by something else). Otherwise (fixed scale, or a
  // part truly beyond the tolerance) it fits nowhere exactly.
  bool fittedFully = false;
  // The refinement lays the model's points on edges as closely as subpixel edges are located on a
  // sharp image (least_squares_refinement.hpp, kExactFitCutoff).
  bool exactFit = false;
};

// The most score a refinement that fits the part may give up: what a displaced feature (a hole
// out of place, a slightly different pad) holds of the model, a few hundredths. A refinement
// that loses more has locked onto something that is not the part (texture, specular spots, a
// neighbour's edges), however many points it lays on edges there.
inline constexpr double kMaxRefinementScoreLoss = 0.1;

// The share of its support by which a start must beat a full fit to be kept: a pose a hundredth
// of a pixel from the fit's, nearer the optimum of the support's own weighting, lays a few tenths
// of a point more on edges (592.3 against 591.3 of 600 points on an exact part: the start, 0.017
// px off, was kept and the pose returned depended on where the refinement started); a pose tilted
// towards a displaced feature lays a tenth more.
inline constexpr double kSupportTolerance = 0.01;

// True when the refined pose is kept. Where the refinement fitted the part fully, the support
// decides (within kSupportTolerance) within kMaxRefinementScoreLoss: a pose tilted towards a
// displaced feature may score a little higher than the one that fits the rest of the part. An exact
// fit may lose more: the score tolerates a pixel or two, and next to an occluder a pose 1-2 px off
// collects the occluder's border and outscores the true one by 0.1-0.14, while the refinement from
// there lays the visible part's points on its edges within a few hundredths of a pixel (a fit
// locked onto texture or a neighbour's edges lays them tenths of a pixel off). Elsewhere the score
// decides. The minimum score plays no part: it filters matches, it does not choose their poses.
bool keepsRefinedPose(const RefinementOutcome& outcome);

// The score a match reports when its refined pose is kept: the better of the two. The refinement
// may give up a little similarity to fit the whole part (a displaced feature, an occluder's
// border along the model), and whether the part is there was judged by the search; a kept
// refinement never turns a part found into one missed (it did with the refined score: a 40%
// occluded part, refined onto its true pose, fell from 0.503 to 0.488 below a minimum of 0.5).
double keptRefinementScore(const RefinementOutcome& outcome);

}  // namespace facet::shape_detail
