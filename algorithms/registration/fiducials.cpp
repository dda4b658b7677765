#include "algorithms/registration/fiducials.hpp"

#include "algorithms/geometry/similarity_fit.hpp"

namespace facet {

FiducialResult locateFiducials(const cv::Mat& ref, const std::vector<cv::Point2d>& refMarks,
                               const cv::Mat& image, RegistrationParams params) {
  FiducialResult out;
  if (refMarks.size() < 2) {
    out.status = Status<RegistrationFailure>::failed(
        RegistrationFailure::TooFewFiducials,
        "at least two reference marks are needed to give a rotation");
    return out;
  }
  const RegistrationResult r = registerImages(ref, image, params);
  if (!r.status.ok()) {
    out.status = r.status;
    return out;
  }
  out.H = r.H;
  for (const auto& m : refMarks) out.marks.push_back(mapPoint(r.H, m));
  // Similarity that carries the reference marks onto the found ones (least squares): its angle
  // is the part's rotation.
  const auto similarity = fitSimilarity(refMarks, out.marks);
  if (!similarity) {
    out.status = Status<RegistrationFailure>::failed(RegistrationFailure::TooFewFiducials,
                                                     "the reference marks coincide");
    return out;
  }
  out.rotationDeg = similarity->rotationDeg;
  out.scale = similarity->scale;
  return out;
}

}  // namespace facet
