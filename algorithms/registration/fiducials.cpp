#include "algorithms/registration/fiducials.hpp"

#include <cmath>
#include <numbers>

namespace facet {

FiducialResult locateFiducials(const cv::Mat& ref, const std::vector<cv::Point2d>& refMarks,
                               const cv::Mat& image, RegistrationParams params) {
  FiducialResult out;
  if (refMarks.size() < 2) {
    out.failureCause = "too_few_fiducials";
    out.message = "at least two reference marks are needed to give a rotation";
    return out;
  }
  const RegistrationResult r = registerImages(ref, image, params);
  if (!r.ok) {
    out.failureCause = r.failureCause;
    out.message = r.message;
    return out;
  }
  out.H = r.H;
  for (const auto& m : refMarks) out.marks.push_back(mapPoint(r.H, m));
  // Similarity that carries the reference marks onto the found ones (least squares): its angle
  // is the part's rotation. With centred points p, q: q = s R(a) p, R(a) = [[c, s], [-s, c]].
  cv::Point2d cp(0, 0), cq(0, 0);
  for (std::size_t i = 0; i < refMarks.size(); ++i) {
    cp += refMarks[i];
    cq += out.marks[i];
  }
  cp *= 1.0 / refMarks.size();
  cq *= 1.0 / refMarks.size();
  double sc = 0, ss = 0, pp = 0;
  for (std::size_t i = 0; i < refMarks.size(); ++i) {
    const cv::Point2d p = refMarks[i] - cp, q = out.marks[i] - cq;
    sc += p.x * q.x + p.y * q.y;
    ss += p.y * q.x - p.x * q.y;
    pp += p.x * p.x + p.y * p.y;
  }
  if (!(pp > 0)) {
    out.failureCause = "too_few_fiducials";
    out.message = "the reference marks coincide";
    return out;
  }
  out.rotationDeg = std::atan2(ss, sc) * 180.0 / std::numbers::pi;
  out.scale = std::hypot(sc, ss) / pp;
  out.ok = true;
  return out;
}

}  // namespace facet
