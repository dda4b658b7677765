#pragma once
// Normalised cross-correlation of log-polar windows over cyclic angle shifts and ring shifts,
// and all-pairs matching of two window sets.
//
// The score of a window pair is the best NCC over ring shifts s in [-ringShifts, ringShifts]
// (the reference uses its central `rings` rows, the other window rows shifted by s) and all
// cyclic angle shifts. Three accelerations, each switchable, leave the result identical:
//  - projections: the angle profile (sum over rings) and the radius profile (sum over angles)
//    give exact upper bounds of the NCC for every shift at the cost of 1D correlations; shifts
//    are tried in the order of their bound and abandoned once the bound cannot beat the best;
//  - sumTables: NCC denominators come from per-ring sum tables instead of loops;
//  - jensen: the correlation sum is accumulated ring by ring and abandoned as soon as the
//    partial sum plus a bound on the remaining rings (Jensen / Cauchy-Schwarz: the remaining
//    covariance cannot exceed the product of the remaining deviations) cannot beat the best.
// All sums are integers, so the accelerated scores are bit-identical to the plain ones.

#include <cstdint>
#include <vector>

#include "algorithms/registration/log_polar_window.hpp"

namespace facet {

struct NccAccelerations {
  bool projections = true;
  bool sumTables = true;
  bool jensen = true;
};

struct NccMatchParams {
  double minScore = 0.75;  // NCC below this is not a match
  // Image windows kept per reference window, best first. 1: the best one, and an image window
  // claimed by several reference windows keeps only its best (one-to-one). More: on a repeated
  // pattern the true partner is often not the best scoring of its look-alikes, so the best
  // `candidates` are all kept and the geometric consensus chooses; no one-to-one then.
  int candidates = 1;
  NccAccelerations accelerations;
};

struct WindowScore {
  double score = -2.0;  // best NCC; -2 when nothing beat the threshold
  int ringShift = 0;    // s: image rings are shifted by s (scale image/ref = ringRatio^s)
  int angleShift = 0;   // t: image angle index = ref angle index + t
};

// Best NCC of `ref` against `image` that is >= threshold (ties: smallest ring, then angle
// shift). Returns score -2 when no shift reaches the threshold.
WindowScore compareWindows(const LogPolarWindow& ref, const LogPolarWindow& image, int ringShifts,
                           double threshold, const NccAccelerations& acc);

struct WindowMatch {
  int ref = -1;    // index into the reference windows
  int image = -1;  // index into the image windows
  WindowScore best;
};

// For every reference window the best image window (score >= minScore), then one-to-one: an
// image window claimed by several reference windows keeps the best-scoring one. With
// params.candidates > 1 the best that many per reference window, and no one-to-one.
std::vector<WindowMatch> matchWindows(const std::vector<LogPolarWindow>& ref,
                                      const std::vector<LogPolarWindow>& image, int ringShifts,
                                      const NccMatchParams& params);

// What matchWindows gives with candidates = 1, from what it gave with more candidates (the same
// windows and minimum score): each reference window's best, then one-to-one. Where both are
// needed, one all-pairs pass instead of two.
std::vector<WindowMatch> bestOfEach(const std::vector<WindowMatch>& candidates);

}  // namespace facet
