#pragma once
// Caliper: edges and edge pairs along a rotated rectangle or an arc (Halcon's measure_pos /
// measure_pairs, Cognex Caliper).
//
// The grey profile along the axis, averaged across the width (grey_profile.hpp), is searched for
// step edges with a symmetric-area subpixel estimator (profile_edges.hpp); neighbouring edges
// whose blurs overlap (a narrow bar or slot, the teeth of a comb a few blur widths apart) are
// fitted together (edge_cluster_fit.hpp). Edges are filtered by polarity and minimum amplitude and
// selected (first, last, strongest, all); pairs are neighbouring edges of opposite polarity whose
// first edge has the requested polarity. Positions are signed distances from the path's centre
// along its axis, in pixels.

#include <string>
#include <vector>

#include <opencv2/core.hpp>

#include "algorithms/measure/measure_failure.hpp"
#include "algorithms/measure/measuring_path.hpp"
#include "algorithms/measure/profile_edges.hpp"
#include "algorithms/status/status.hpp"

namespace facet {

enum class EdgePolarity { Any, Rising, Falling };  // rising = dark to light along the axis
enum class EdgeSelect { All, First, Last, Strongest };

struct CaliperParams {
  EdgePolarity polarity = EdgePolarity::Any;
  EdgeSelect select = EdgeSelect::All;
  double minAmplitude = 20.0;  // grey levels (8-bit scale), |step| of an edge
  bool pairs = false;          // also pair the edges
  GreyProfileParams sampling;  // profile sampling steps
  ProfileEdgeParams edges;     // estimator settings (its minAmplitude is replaced by the above)
};

struct CaliperEdge {
  cv::Point2d point;     // image position on the axis
  double position = 0;   // signed distance from the centre along the axis, pixels
  double amplitude = 0;  // signed grey step: > 0 rising
  // The sensor clipped the profile beside it (an overexposed backlight): the position lies
  // towards the unclipped side by up to a pixel (ProfileEdge::clipped); lower the exposure.
  bool clipped = false;
};

struct CaliperPair {
  CaliperEdge first, second;  // in axis order
  cv::Point2d centre;         // image position of the pair's middle
  double position = 0;        // axis position of the middle
  double width = 0;           // second.position - first.position, pixels
};

struct CaliperResult {
  std::vector<CaliperEdge> edges;  // selected edges, sorted by position
  std::vector<CaliperPair> pairs;  // selected pairs (when asked), sorted by position
  bool partial = false;            // part of the path lay outside the image
  Status<MeasureFailure> status;
};

// Measures along `path` in a CV_8UC1 / CV_16UC1 image (other types throw std::invalid_argument).
CaliperResult measureCaliper(const cv::Mat& image, const MeasuringPath& path,
                             const CaliperParams& params = {});

}  // namespace facet
