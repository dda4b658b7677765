#pragma once
// Edges a few blur widths apart -- a bar, a slot, a pin seen edge-on, the teeth of a comb, a
// thread -- fitted together in a grey profile.
//
// profile_edges.hpp fits each edge on its own side of the midpoint to its neighbour, with the
// neighbour's fitted step subtracted, then balances the area about the edge. Once neighbouring
// edges' blurs overlap (closer than about four blur widths), each sees the other's model error: a
// bar of 4 px under a blur of 1.5 px reads 0.12 px too wide, one of 3 px 0.44 px (noise-free);
// where several such edges follow each other (two 4 px bars 4 px apart under that blur) the
// single-edge fits degenerate into pairs of huge opposite steps on one place, or die. Here the
// edges of such a cluster are one model, a + sum_k b_k Phi((s - e_k) / w) + g (s - c), with one
// blur w (one lens at one place), over the cluster's span and up to `window` beyond its end edges:
// no window is cut between them, and the overlap is what the model describes. A bar is symmetric
// about its centre, so the erf standing in for the blur convolved with the pixel cannot move the
// centre; it moves the width by far less than the single-edge fits did (measured in
// bench/independent_renders).

#include <vector>

#include "algorithms/measure/grey_profile.hpp"
#include "algorithms/measure/profile_edges.hpp"

namespace facet {

// The caliper's edges (ProfileEdgeFinder::find, `single`, and its candidates(), `peaks`) with
// those that crowd refitted together; the others keep the single-edge estimate.
// - Neighbours crowd where their blurs overlap (3 w reaches into the span over which the other
//   balances its area, ProfileEdgeParams::areaHalfWidth: below that the single-edge estimate is
//   unbiased, bars of 4.2 w: 0.002 px noise-free; above it the joint fit is, bars of 2.6 w:
//   0.12 px before, 0.01 px), or where one is a peak whose single fit failed -- died, came out
//   weaker than an edge, or degenerated into a step well beyond the grey values the profile spans
//   while another peak lay in its window -- and the other lies within its window: that failure
//   is what a neighbour does to a single fit. Crowding is judged on the derivative's peaks, where
//   the edges show: a single fit next to a neighbour that died is pulled away from its own peak.
//   A peak weaker than `params.minAmplitude` without a fit of its own (texture, noise) takes no
//   part.
// - A cluster's joint fit starts at each peak from the plausible single fit that came from it
//   (same polarity, within a pixel), else from the peak itself with the profile's typical fitted
//   blur. A step of the joint fit larger than the sensor's range (1.2 GreyProfile::clipLevel: one
//   start too many, two steps grown huge that cancel), else one weaker than the minimum
//   amplitude, is left out and the rest fitted again. Plausible fits that came from no peak are
//   replaced by the joint fit of the cluster they lie in.
// - A cluster of more than 12 edges (the fit's cost grows with the cube of its edges: a long comb,
//   a row of connector pins) is fitted in blocks of up to 8, each together with two edges either
//   side and the rest of the chain subtracted, in two passes. A cluster whose joint fit fails
//   keeps its plausible single fits.
//   Neither a failed single fit nor a step larger than the sensor's range is ever reported.
// Sorted by position.
std::vector<ProfileEdge> refitCrowdedEdges(const GreyProfile& profile,
                                           const std::vector<ProfileEdge>& single,
                                           const std::vector<ProfileEdge>& peaks,
                                           const ProfileEdgeParams& params);

}  // namespace facet
