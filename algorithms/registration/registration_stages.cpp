// The default registration pipeline: the fast plain-Harris stage first, Harris-Affine regions
// when that finds no transform it can stand on. Why not always Harris-Affine: its shape
// adaptation costs several times the plain windows, and most pairs (small viewpoint changes,
// rotation, zoom) do not need it; why not plain Harris alone: beyond about 30 degrees of
// viewpoint change its windows no longer match, and the few chance matches left can still agree
// on a wrong transform.
#include "algorithms/registration/register_images.hpp"

namespace facet {

RegistrationResult registerImages(const cv::Mat& ref, const cv::Mat& image,
                                  const RegistrationParams& params) {
  RegistrationResult fast = registerSingleStage(ref, image, params);
  if (params.affineRegions || !params.escalateToAffine ||
      (fast.ok && fast.globalInliers >= params.affineBelowInliers))
    return fast;
  RegistrationParams affine = params;
  affine.affineRegions = true;
  RegistrationResult adapted = registerSingleStage(ref, image, affine);
  adapted.escalated = fast.escalated = true;
  if (!adapted.ok && fast.ok) return fast;
  if (adapted.ok && fast.ok && adapted.globalInliers <= fast.globalInliers) return fast;
  return adapted;
}

}  // namespace facet
