#pragma once
// Two edges of opposite polarity a few blur widths apart -- a bar, a slot, a pin seen edge-on --
// fitted together in a grey profile.
//
// profile_edges.hpp fits each edge on its own side of the midpoint to its neighbour, with the
// neighbour's fitted step subtracted, then balances the area about the edge. Once the two edges'
// blurs overlap (closer than about four blur widths), each sees the other's model error: a bar of
// 4 px under a blur of 1.5 px reads 0.12 px too wide, one of 3 px 0.44 px (noise-free). Here both
// edges are one model, a + b1 Phi((s - e1) / w) + b2 Phi((s - e2) / w) + g (s - c), with one blur w
// (one lens at one place), over the pair's span and up to `window` beyond either edge: no window is
// cut between them, and the overlap is what the model describes. A bar is symmetric about its
// centre, so the erf standing in for the blur convolved with the pixel cannot move the centre; it
// moves the width by far less than the single-edge fits did (measured in
// bench/independent_renders).

#include <optional>
#include <span>

#include "algorithms/measure/grey_profile.hpp"
#include "algorithms/measure/profile_edges.hpp"

namespace facet {

// Whether the single-edge estimates of two neighbouring edges see each other's model error: the
// blur of one (3 w) reaches into the span over which the other balances its area
// (ProfileEdgeParams::areaHalfWidth). Below that the single-edge estimate is unbiased (bars of
// 4.2 w: 0.002 px noise-free), above it the joint fit is (bars of 2.6 w: 0.12 px before, 0.01 px).
bool blursOverlap(const ProfileEdge& first, const ProfileEdge& second, double areaHalfWidth);

struct BarEdges {
  ProfileEdge first, second;  // in axis order; blur is the common w
};

// Fits the pair (first.position < second.position, amplitudes of opposite sign) over its span
// and up to `window` pixels beyond either edge, short of the midpoint to any edge of `others` (the
// profile's other edges, whose fitted steps are subtracted first). Empty when the fit degenerates
// or leaves the span; the caller keeps the single-edge positions then.
std::optional<BarEdges> fitBarProfile(const GreyProfile& profile, const ProfileEdge& first,
                                      const ProfileEdge& second,
                                      std::span<const ProfileEdge> others, double window);

}  // namespace facet
