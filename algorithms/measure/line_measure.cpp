#include "algorithms/measure/line_measure.hpp"

#include <algorithm>
#include <cmath>
#include <vector>

#include "algorithms/measure/edge_cluster_fit.hpp"

namespace facet {
namespace {

LineMeasurement failed(MeasureFailure cause, std::string message, bool partial) {
  LineMeasurement m;
  m.status = Status<MeasureFailure>::failed(cause, std::move(message));
  m.partial = partial;
  return m;
}

}  // namespace

LineMeasurement measureLine(const cv::Mat& image, const MeasuringRect& rect,
                            const LineMeasureParams& params) {
  if (!(rect.length > 0) || !(rect.width > 0))
    return failed(MeasureFailure::ZeroSize, "the line rectangle has zero length or width", false);
  if (!(params.spacing > 0) || !(params.stationWidth > 0))
    throw std::invalid_argument("line: spacing and station width must be positive");
  const MeasuringPath along(rect);
  ProfileEdgeParams ep = params.edges;
  ep.minAmplitude = params.minAmplitude;

  // One set of buffers (and one derivative kernel) for every station.
  GreyProfileSampler sampler(params.sampling);
  ProfileEdgeFinder finder(ep);

  LineMeasurement m;
  std::vector<bool> clipped;  // of each edge point
  const int count = std::max(1, static_cast<int>(std::floor(rect.length / params.spacing)));
  const double first = -(count - 1) * params.spacing / 2.0;
  int contrasted = 0;
  for (int k = 0; k < count; ++k) {
    const cv::Point2d c = along.at(first + k * params.spacing, 0.0);
    const MeasuringPath across(
        MeasuringRect{c.x, c.y, rect.width, params.stationWidth, rect.angle - 90.0});
    const GreyProfile& profile = sampler.sample(image, across);
    if (profile.values.size() < 6) {
      m.partial = true;
      continue;
    }
    ++m.stations;
    m.partial = m.partial || profile.partial;
    const auto [lo, hi] = std::minmax_element(profile.values.begin(), profile.values.end());
    if (*hi - *lo >= params.minAmplitude) ++contrasted;
    // Edges that crowd (a thin slot or a comb beside the line) are fitted together: their single
    // fits can degenerate into huge steps, which would be taken for the strongest.
    const ProfileEdge* best = nullptr;
    const std::vector<ProfileEdge> edges =
        refitCrowdedEdges(profile, finder.find(profile), finder.candidates(), ep);
    for (const ProfileEdge& e : edges) {
      const bool wanted = params.polarity == EdgePolarity::Any ||
                          (params.polarity == EdgePolarity::Rising) == (e.amplitude > 0);
      if (wanted && (!best || std::abs(e.amplitude) > std::abs(best->amplitude))) best = &e;
    }
    if (best) {
      m.edgePoints.push_back(across.at(best->position, 0.0));
      clipped.push_back(best->clipped);
    }
  }
  if (m.stations == 0)
    return failed(MeasureFailure::OutsideImage, "the line rectangle lies outside the image", true);
  if (contrasted == 0)
    return failed(MeasureFailure::NoContrast, "no contrast in the line rectangle", m.partial);
  if (m.edgePoints.size() < 3)
    return failed(MeasureFailure::TooFewPoints,
                  "only " + std::to_string(m.edgePoints.size()) +
                      " edge points of the requested polarity and amplitude",
                  m.partial);
  const auto fit = fitLineRobust(m.edgePoints, params.fit);
  if (!fit)
    return failed(MeasureFailure::TooFewPoints, "the edge points do not form a line", m.partial);

  // Orient the line along the rectangle's axis and take the inliers' extent on it.
  const LineSegment seg = inlierSegment(*fit, m.edgePoints, along.axisAt(0.0));
  m.p1 = seg.p1;
  m.p2 = seg.p2;
  m.angle = std::atan2(-seg.direction.y, seg.direction.x) * 180.0 / CV_PI;
  m.rms = fit->rms;
  m.straightness = fit->straightness;
  m.points = static_cast<int>(fit->inliers.size());
  m.inliers = fit->inliers;
  for (const int i : m.inliers) m.clippedPoints += clipped[static_cast<std::size_t>(i)] ? 1 : 0;
  return m;
}

}  // namespace facet
