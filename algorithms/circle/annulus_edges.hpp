#pragma once
// Subpixel edge points inside an annulus, with Canny thresholds chosen from that annulus alone.
//
// A generic automatic threshold (Otsu on the gradient histogram, noise from its median) assumes
// that edges are rare in the region; in a narrow annulus around a rim they are not (a third of
// its pixels lie on the blurred rim), and clutter inside it pulls Otsu up. So here both thresholds
// come from two robust statistics of the annulus:
//   - the rim strength M: the median, over angular sectors, of the largest gradient magnitude in
//     each sector (occlusion and clutter spoil fewer than half of the sectors);
//   - the noise: Immerkaer's estimate, the median absolute response of the mask
//     [1 -2 1; -2 4 -2; 1 -2 1] (zero on planes and on straight edges along the axes), scaled to
//     the gradient operator's noise gain.
// high = max(M / 2, 4.5 sigma_g), low = max(0.4 high, 2.5 sigma_g); strong enough to reject noise,
// low enough to keep a rim of half the typical strength (illumination gradients, low contrast).

#include <optional>
#include <vector>

#include <opencv2/core.hpp>

#include "algorithms/edges/subpixel_edges.hpp"

namespace facet {

struct AnnulusEdges {
  std::vector<EdgePoint> points;  // image coordinates
  int annulusPixels = 0;          // pixels of the annulus inside the image (0: none)
  double lowThreshold = 0.0;      // grey levels per pixel (8-bit scale)
  double highThreshold = 0.0;
  double noiseSigma = 0.0;  // estimated image noise, grey levels (8-bit scale)
  // Whether the noise estimate met pixels the sensor clipped (0 or the type's largest value) in
  // the annulus: its masks there are left out (they read the clip as a noise-free image).
  bool clipped = false;
};

// Edge points of `image` (CV_8UC1 or CV_16UC1) whose pixels lie at distances [rIn, rOut] from
// `centre`. `low`/`high` override the automatic thresholds when both are given.
AnnulusEdges detectAnnulusEdges(const cv::Mat& image, cv::Point2d centre, double rIn, double rOut,
                                std::optional<double> low = {}, std::optional<double> high = {});

}  // namespace facet
