#pragma once
// Blob analysis: threshold a region, label its connected components (OpenCV's
// connectedComponentsWithStats) and measure each component (Halcon's threshold / connection /
// area_center, Cognex Blob).
//
// Why a grey-value area: counting thresholded pixels errs by about the square root of the
// perimeter in pixels (1-2% for a disc of radius 6). Blur and pixel integration conserve light, so
// the sum over the blob and a band around it of (grey - background) / (object - background) is
// the object's area whatever the blur, with noise as the only error; the levels are the medians
// of the blob's core and of a ring outside it. Centroid and ellipse come from the same weights.

#include <limits>
#include <string>
#include <vector>

#include <opencv2/core.hpp>

#include "algorithms/measure/measure_failure.hpp"
#include "algorithms/status/status.hpp"

namespace facet {

enum class BlobPolarity { Light, Dark };  // blobs lighter / darker than their surroundings
enum class BlobThreshold { Fixed, Otsu, RelativeToMedian };

struct BlobParams {
  cv::Rect roi;  // image pixels; empty = the whole image; clipped to the image
  BlobThreshold mode = BlobThreshold::Otsu;
  // Fixed: the grey level (8-bit scale) separating blobs from background. RelativeToMedian: the
  // distance in grey levels from the region's median (above it for light blobs, below for dark).
  double threshold = 128.0;
  BlobPolarity polarity = BlobPolarity::Light;
  double minArea = 0.0;  // pixels^2
  double maxArea = std::numeric_limits<double>::infinity();
  double minRoundness = 0.0;  // minor / major axis of the blob's ellipse, 0..1
  bool greyArea = true;       // area, centroid and ellipse from grey values (else pixel counts)
  double minContrast = 10.0;  // grey levels: a region spanning less has no contrast
  bool keepCoverage = false;  // keep each blob's coverage (Blob::coverage)
};

// The share of each pixel a blob covers (the weights its area and moments sum), over an image
// box: what a caller needs to measure the blob in another geometry, e.g. a tilted plane seen
// through a lens, where one scale at the centroid is not the blob's (plane_blob.hpp).
struct BlobCoverage {
  cv::Rect box;     // image pixels
  cv::Mat1f share;  // box.size(); 0 outside the blob
};

struct Blob {
  cv::Point2d centroid;                     // image pixels
  double area = 0;                          // pixels^2
  int pixels = 0;                           // thresholded pixel count
  cv::Rect bbox;                            // image pixels, of the thresholded pixels
  double majorRadius = 0, minorRadius = 0;  // semi-axes of the equal-moment ellipse, pixels
  double angle = 0;            // major axis, degrees counter-clockwise on screen, (-90, 90]
  bool touchesBorder = false;  // touches the region's border (may be cut off)
  BlobCoverage coverage;       // empty unless BlobParams::keepCoverage
};

struct BlobResult {
  std::vector<Blob> blobs;  // sorted by area, largest first
  double threshold = 0;     // the grey level used (8-bit scale)
  bool partial = false;     // the region was clipped to the image
  Status<MeasureFailure> status;
};

// CV_8UC1 / CV_16UC1 image (other types throw std::invalid_argument).
BlobResult analyseBlobs(const cv::Mat& image, const BlobParams& params = {});

}  // namespace facet
