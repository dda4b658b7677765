#include "algorithms/measure/caliper.hpp"

#include <algorithm>
#include <cmath>

#include "algorithms/measure/edge_cluster_fit.hpp"

namespace facet {
namespace {

bool matches(EdgePolarity polarity, double amplitude) {
  return polarity == EdgePolarity::Any || (polarity == EdgePolarity::Rising) == (amplitude > 0);
}

template <class T, class Strength>
std::vector<T> choose(std::vector<T> items, EdgeSelect select, Strength strength) {
  if (items.empty() || select == EdgeSelect::All) return items;
  if (select == EdgeSelect::First) return {items.front()};
  if (select == EdgeSelect::Last) return {items.back()};
  return {*std::max_element(items.begin(), items.end(),
                            [&](const T& x, const T& y) { return strength(x) < strength(y); })};
}

CaliperResult failed(MeasureFailure cause, std::string message, bool partial = false) {
  CaliperResult r;
  r.status = Status<MeasureFailure>::failed(cause, std::move(message));
  r.partial = partial;
  return r;
}

}  // namespace

CaliperResult measureCaliper(const cv::Mat& image, const MeasuringPath& path,
                             const CaliperParams& params) {
  if (!(path.length() > 0) || !(path.width() > 0))
    return failed(MeasureFailure::ZeroSize, "the caliper has zero length or width");
  const GreyProfile profile = sampleGreyProfile(image, path, params.sampling);
  if (profile.values.size() < 6)
    return failed(MeasureFailure::OutsideImage, "the caliper lies outside the image");
  const auto [lo, hi] = std::minmax_element(profile.values.begin(), profile.values.end());
  if (*hi - *lo < params.minAmplitude)
    return failed(MeasureFailure::NoContrast,
                  "no contrast in the caliper: grey values span " + std::to_string(*hi - *lo) +
                      " < minimum amplitude " + std::to_string(params.minAmplitude),
                  profile.partial);

  ProfileEdgeParams ep = params.edges;
  ep.minAmplitude = params.minAmplitude;
  ProfileEdgeFinder finder(ep);
  const std::vector<ProfileEdge> found =
      refitCrowdedEdges(profile, finder.find(profile), finder.candidates(), ep);
  std::vector<CaliperEdge> all;
  for (const ProfileEdge& e : found)
    all.push_back({path.at(e.position, 0.0), e.position, e.amplitude, e.clipped});

  CaliperResult result;
  result.partial = profile.partial;
  std::vector<CaliperEdge> wanted;
  for (const CaliperEdge& e : all)
    if (matches(params.polarity, e.amplitude)) wanted.push_back(e);
  if (wanted.empty())
    return failed(MeasureFailure::NoEdge, "no edge of the requested polarity and amplitude",
                  profile.partial);
  result.edges =
      choose(wanted, params.select, [](const CaliperEdge& e) { return std::abs(e.amplitude); });

  if (params.pairs) {
    std::vector<CaliperPair> pairs;
    for (std::size_t i = 0; i + 1 < all.size(); ++i) {
      const CaliperEdge &a = all[i], &b = all[i + 1];
      if ((a.amplitude > 0) == (b.amplitude > 0) || !matches(params.polarity, a.amplitude))
        continue;
      CaliperPair pr{a, b, {}, 0.5 * (a.position + b.position), b.position - a.position};
      pr.centre = path.at(pr.position, 0.0);
      pairs.push_back(pr);
      ++i;  // an edge belongs to one pair
    }
    if (pairs.empty())
      return failed(MeasureFailure::NoPair, "no pair of edges of opposite polarity",
                    profile.partial);
    result.pairs = choose(pairs, params.select, [](const CaliperPair& p) {
      return std::min(std::abs(p.first.amplitude), std::abs(p.second.amplitude));
    });
  }
  return result;
}

}  // namespace facet
