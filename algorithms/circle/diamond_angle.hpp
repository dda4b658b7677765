#pragma once
// The "diamond angle": a monotonic stand-in for the polar angle about a centre, in [0, 4), with
// no atan2 in the loops over a band's pixels. Bins of equal width in it are within a factor 1.5 of
// equal angles, which is all the angular statistics of an annulus need (its sectors' strongest
// gradients, the rim fit's coverage bins).

namespace facet::diamond_angle {

// 0 at the centre itself. Without a branch, so that loops over pixels vectorise.
double of(double dx, double dy);

// The bin, of `bins` equal widths in the diamond angle, of the offset (dx, dy) from the centre.
int binOf(double dx, double dy, int bins);

// binOf for the n pixels from column x0 on of the row dy below the centre (centreX its column),
// the same values four pixels at a time. `bin` has room for n rounded up to a multiple of 4 (the
// last group's extra lanes are written too).
void rowBins(int x0, int n, double centreX, double dy, int bins, int* __restrict bin);

}  // namespace facet::diamond_angle
