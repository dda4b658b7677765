#pragma once
// Subpixel step edges in a grey profile.
//
// A straight edge crossing a caliper is a step blurred by the lens and integrated over the
// pixel -- or blurred on the pixel grid after integration, as a digital filter does. Under both
// image formations the profile across the edge is point-symmetric about the edge position e:
// P(e + u) - m = -(P(e - u) - m) with m the mid level (the blur kernel and the pixel aperture are
// both symmetric). The estimator uses only that symmetry, not a fitted shape:
//
//  1. candidates are extrema of the profile's Gaussian derivative (sigma `smoothing`);
//  2. each edge is fitted with a blurred step on a shaded background, a + b Phi((s - e) / w) +
//     g (s - s0), over its window (up to `window` either side, never past the midpoint to a
//     neighbouring edge, whose own fitted step is subtracted first so that bars a few pixels wide
//     keep both edges unbiased); this gives the levels (a, b), the shading g and a first e. The
//     mid level's noise moves the position as much as the samples at the edge do, so the levels
//     are taken from the whole window (8 px either side: 1.1x the Cramer-Rao bound of the
//     position where 4 px gave 1.3x); the shading term keeps a window cut short on one side (by
//     the profile's end or a neighbour) from reading a sloping background as a shift. Beyond
//     4 px the window reaches only over flat profile: a step too faint to be fitted (a
//     derivative peak above the noise, below half the minimum amplitude) stops it short of its
//     blur, since a faint step 5 px away inside the window would move the edge by a tenth of a
//     pixel;
//  3. e is then moved until the profile's area above and below the mid line m(s) = a + b/2 +
//     g (s - e) balances over [e - R, e + R] (R = `areaHalfWidth`): for a point-symmetric profile
//     that balance point is exactly e for any R, whatever the blur's shape, so the model's shape
//     (an erf standing in for erf convolved with the pixel's footprint) cannot bias the position.
//     The area uses the exact integral of the linearly interpolated samples.

#include <cmath>
#include <vector>

#include "algorithms/geometry/standard_normal.hpp"
#include "algorithms/measure/grey_profile.hpp"

namespace facet {

struct ProfileEdgeParams {
  double smoothing = 1.0;           // pixels: sigma of the derivative that finds candidates
  double minAmplitude = 20.0;       // grey levels (8-bit scale): smallest |step| kept
  double window = 8.0;              // pixels either side of an edge in its step fit
  double areaHalfWidth = 1.5;       // pixels either side in the symmetric-area refinement
  bool symmetricRefinement = true;  // step 3 above; off reports the step fit's e
};

struct ProfileEdge {
  double position = 0;   // axis position, pixels (as GreyProfile::positionAt)
  double amplitude = 0;  // signed grey step along the axis: > 0 dark to light (rising)
  double blur = 0;       // fitted step width w, pixels (blur sigma with the pixel's footprint)
  // Samples the sensor clipped (GreyProfile::clipLevel, or 0) lie in its window: the step is cut
  // on that side and the position lies towards the other, by up to a pixel (a backlight 1.6 times
  // the clip: 0.57 px). The profile's interpolation mixes clipped pixels with others, so no
  // model of the profile alone undoes it; lower the exposure.
  bool clipped = false;
};

// Another edge's blurred step (at `edge`, step `amplitude`, erf width `width`) at axis position s,
// as an edge at `self` sees it in its window: one ahead adds its rising part, one behind
// subtracts the part it has not yet completed, so that the window keeps the level its own edge
// starts from. 0 beyond 8 widths. The single-edge fits and the joint fits of crowded edges
// (edge_cluster_fit.hpp) subtract their neighbours this way.
inline double neighbourStep(double edge, double amplitude, double width, double self, double s) {
  const double z = (s - edge) / width;
  if (std::abs(z) > 8) return 0.0;
  const double cdf = standard_normal::normal(z).cdf;
  return edge > self ? amplitude * cdf : amplitude * (cdf - 1.0);
}

// Every edge of either polarity with |amplitude| >= minAmplitude, sorted by position.
std::vector<ProfileEdge> findProfileEdges(const GreyProfile& profile,
                                          const ProfileEdgeParams& params = {});

// The same search over many profiles with one set of parameters (a line's cross calipers): the
// derivative's kernel is made once and the working buffers are kept, so that a profile costs no
// allocation once the buffers have grown.
class ProfileEdgeFinder {
 public:
  explicit ProfileEdgeFinder(const ProfileEdgeParams& params = {});
  ~ProfileEdgeFinder();
  ProfileEdgeFinder(const ProfileEdgeFinder&) = delete;
  ProfileEdgeFinder& operator=(const ProfileEdgeFinder&) = delete;

  // As findProfileEdges(profile, params); the result lives until the next call.
  const std::vector<ProfileEdge>& find(const GreyProfile& profile);

  // The last find()'s candidates, in axis order: the derivative's peaks strong enough to be
  // fitted (position from the parabola through the peak, amplitude as the peak's height reads
  // it, blur 0). Where edges crowd, a joint fit starts from them (edge_cluster_fit.hpp).
  [[nodiscard]] const std::vector<ProfileEdge>& candidates() const { return candidates_; }

 private:
  struct Step;
  void derivative(const GreyProfile& profile);
  void findNear(std::size_t self);
  [[nodiscard]] double neighbours(std::size_t self, double s) const;
  bool fitStep(const GreyProfile& profile, std::size_t self);

  ProfileEdgeParams params_;
  double kernelStep_ = 0;           // the profile step the kernel was made for
  std::vector<double> kernel_;      // derivative taps 1..r (index 0 unused)
  double kernelNorm_ = 0;           // their response to a unit slope
  std::vector<double> padded_;      // the profile with its ends repeated r times
  std::vector<double> slope_;       // the derivative
  std::vector<Step> steps_;         // candidates, then fitted steps
  std::vector<std::size_t> near_;   // steps reaching into the current step's window
  std::vector<double> faint_;       // positions of steps too faint to fit (window stops)
  std::vector<double> magnitudes_;  // |slope|, for the noise level
  std::vector<double> window_;      // the current step's samples, neighbours removed
  std::vector<ProfileEdge> found_, edges_, candidates_;
};

}  // namespace facet
