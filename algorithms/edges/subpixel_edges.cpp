#include "algorithms/edges/subpixel_edges.hpp"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <limits>
#include <optional>
#include <stdexcept>
#include <string>

#include "algorithms/edges/auto_thresholds.hpp"
#include "algorithms/edges/canny.hpp"
#include "algorithms/edges/curvature_bias.hpp"
#include "algorithms/edges/edge_linking.hpp"
#include "algorithms/edges/edge_profile_fit.hpp"
#include "algorithms/edges/facet_model.hpp"

namespace facet {
namespace {

// Keep a point when the edge line crosses the pixel's row (steep edges) or column (flat edges)
// inside the pixel: one point per row or column crossing, never two on a diagonal.
bool crossesInsidePixel(const EdgePoint& point, cv::Point pixel) {
  const double rho = (point.position - cv::Point2d(pixel)).dot(point.normal);
  const double axis = std::max(std::abs(point.normal.x), std::abs(point.normal.y));
  return std::abs(rho) <= 0.5 * axis;
}

// How far the image's pixel centres reach from p along the unit direction d.
double imageReach(cv::Point2d p, cv::Point2d d, cv::Size size) {
  double reach = std::numeric_limits<double>::infinity();
  if (d.x > 1e-12) reach = std::min(reach, (size.width - 1 - p.x) / d.x);
  if (d.x < -1e-12) reach = std::min(reach, -p.x / d.x);
  if (d.y > 1e-12) reach = std::min(reach, (size.height - 1 - p.y) / d.y);
  if (d.y < -1e-12) reach = std::min(reach, -p.y / d.y);
  return reach;
}

// The final one-point-per-crossing rule on the refined (and curvature-corrected) positions:
// noise can make two pixels of a row local maxima whose facet points both pass; the refined
// points, averaged over the whole window, cannot both cross the row inside their pixels.
void dropPointsOutsideTheirPixel(EdgeContours& result, const std::vector<cv::Point>& pixels) {
  std::vector<int> newIndex(result.points.size(), -1);
  size_t kept = 0;
  for (size_t i = 0; i < result.points.size(); ++i) {
    if (!crossesInsidePixel(result.points[i], pixels[i])) continue;
    newIndex[i] = static_cast<int>(kept);
    result.points[kept++] = result.points[i];
  }
  result.points.resize(kept);
  for (auto& contour : result.contours) {
    size_t n = 0;
    for (int index : contour)
      if (newIndex[index] >= 0) contour[n++] = newIndex[index];
    contour.resize(n);
  }
  std::erase_if(result.contours, [](const std::vector<int>& c) { return c.empty(); });
}

// The first x in [x, end) whose edge map byte is set, or end. Edge pixels are sparse: eight
// empty pixels are passed over with one comparison.
int nextEdgePixel(const uchar* edges, int x, int end) {
  for (; x + 8 <= end; x += 8) {
    std::uint64_t eight;
    std::memcpy(&eight, edges + x, sizeof eight);
    if (eight != 0) break;
  }
  while (x < end && !edges[x]) ++x;
  return x;
}

// Whether a mask is given for the ROI rather than for the whole image; refuses any other size
// or type, naming the mask.
bool maskCoversRoi(const cv::Mat& mask, const cv::Rect& roi, cv::Size imageSize, const char* name) {
  if (mask.empty()) return false;
  const bool ofRoi = !roi.empty() && mask.size() == roi.size() && mask.size() != imageSize;
  if ((!ofRoi && mask.size() != imageSize) || mask.type() != CV_8UC1)
    throw std::invalid_argument(std::string("detectSubpixelEdges: the ") + name +
                                " must be CV_8UC1 of the image's or the ROI's size");
  return ofRoi;
}

}  // namespace

EdgeContours detectSubpixelEdges(const cv::Mat& image, const EdgeParams& params) {
  EdgeContours result;
  if (image.empty()) return result;
  if (image.type() != CV_8UC1 && image.type() != CV_16UC1)
    throw std::invalid_argument(
        "detectSubpixelEdges: expected an 8-bit or 16-bit single-channel image, got " +
        cv::typeToString(image.type()));
  const bool maskOfRoi = maskCoversRoi(params.mask, params.roi, image.size(), "mask");
  const bool fitMaskOfRoi = maskCoversRoi(params.fitMask, params.roi, image.size(), "fit mask");
  const cv::Point fitMaskOrigin = fitMaskOfRoi ? params.roi.tl() : cv::Point();
  const auto fitsAt = [&](cv::Point pixel) {
    if (params.fitMask.empty()) return true;
    const cv::Point q = pixel - fitMaskOrigin;
    return q.x >= 0 && q.y >= 0 && q.x < params.fitMask.cols && q.y < params.fitMask.rows &&
           params.fitMask.at<uchar>(q) != 0;
  };

  const cv::Rect full(0, 0, image.cols, image.rows);
  const cv::Rect roi = params.roi.empty() ? full : (params.roi & full);
  if (roi.empty()) return result;

  // The gradient covers the ROI plus one pixel for suppression; edge pixels need the facet's
  // 5x5 window inside the image.
  const cv::Rect area = cv::Rect(roi.x - 1, roi.y - 1, roi.width + 2, roi.height + 2) & full;
  const cv::Rect usable = cv::Rect(2, 2, image.cols - 4, image.rows - 4) & roi;
  if (usable.empty()) return result;
  const cv::Rect candidates = usable - area.tl();
  cv::Mat mask;
  if (maskOfRoi) {
    // Pixels of the ring around the ROI are never edge pixels: zero there.
    mask = cv::Mat::zeros(area.size(), CV_8U);
    const cv::Rect covered = params.roi & area;
    params.mask(covered - params.roi.tl()).copyTo(mask(covered - area.tl()));
  } else if (!params.mask.empty()) {
    mask = params.mask(area);
  }

  cv::Mat edges;
  if (params.low && params.high) {
    result.lowThreshold = *params.low;
    result.highThreshold = *params.high;
    edges = cannyInStrips(image, area, result.lowThreshold, result.highThreshold, mask, candidates);
  } else {
    // Automatic thresholds need the whole region's magnitudes first.
    const EdgeGradient gradient = computeEdgeGradient(image, area);
    cv::Mat region = cv::Mat::zeros(area.size(), CV_8U);
    region(candidates).setTo(255);
    if (!mask.empty()) region &= mask;
    const CannyThresholds t = autoCannyThresholds(gradient.magnitude, region);
    result.lowThreshold = t.low;
    result.highThreshold = t.high;
    edges =
        cannyFromGradient(gradient, result.lowThreshold, result.highThreshold, mask, candidates);
  }

  // Facet zero crossings of every Canny pixel.
  std::vector<EdgeSeed> seeds;
  std::vector<double> magnitudes, curvatures;
  for (int y = candidates.y; y < candidates.y + candidates.height; ++y) {
    const auto* e = edges.ptr<uchar>(y);
    const int end = candidates.x + candidates.width;
    for (int x = nextEdgePixel(e, candidates.x, end); x < end; x = nextEdgePixel(e, x + 1, end)) {
      const cv::Point p = cv::Point(x, y) + area.tl();
      const auto z = facetZeroCrossing(fitCubicFacet(image, p));
      if (!z || std::abs(z->rho) > 1.0) continue;
      seeds.push_back({p, z->normal, z->rho});
      curvatures.push_back(z->curvature);
      magnitudes.push_back(z->magnitude);
    }
  }

  // Profile refinement where its window fits in the image, with one blur width per image.
  EdgeProfileParams profile;
  if (params.fitProfile) {
    EdgeBlur blur;
    if (params.blurOnPixelGrid) {
      // The model is known: only the width is estimated, with that model's profiles.
      profile.blurOnPixelGrid = *params.blurOnPixelGrid;
      blur = {estimateEdgeBlur(image, seeds, profile, params.blurSamples, profile.blurOnPixelGrid)
                  .width,
              profile.blurOnPixelGrid};
    } else {
      blur = estimateEdgeBlur(image, seeds, profile, params.blurSamples);
    }
    profile.width = blur.width;
    profile.blurOnPixelGrid = blur.onPixelGrid;
    result.blurOnPixelGrid = blur.onPixelGrid;
    result.blurSigma = std::sqrt(std::max(profile.width * profile.width - 1.0 / 12, 0.0));
    // What separates the offset from the background level is the plateau on either side; keep
    // about 4 widths of it in the window when the blur is wide.
    profile.halfAcross = std::clamp(3.9 * profile.width, profile.halfAcross, 6.5);
  }
  // Near the image's border the fit's window is cut to the image (edge_profile_fit.cpp's
  // gather). It is used while the image still holds two profile widths (at least 2 px) of either
  // side of the edge, across it: with less the levels are not separated from the offset. The
  // facet zero crossing it replaces is biased by up to 0.15 px at a sharp lens (blur sigma 0.5)
  // and 0.03 px at sigma 1.5; with the cut window the points 2-12 px from the border are as
  // precise as the interior's.
  const double plateau = std::max(2.0, 2.0 * profile.width);
  const int reach = edgeProfileReach(profile);
  const cv::Rect fullWindows(reach, reach, image.cols - 2 * reach, image.rows - 2 * reach);
  const auto fitsInImage = [&](cv::Point pixel, const EdgePoint& point) {
    if (!params.fitAtImageBorder) return fullWindows.contains(pixel);
    return imageReach(point.position, point.normal, image.size()) >= plateau &&
           imageReach(point.position, -point.normal, image.size()) >= plateau;
  };
  std::vector<cv::Point> pixels;
  std::vector<double> windowBias;  // per point: kappa coefficient of the fit's window bias
  result.points.reserve(seeds.size());
  pixels.reserve(seeds.size());
  for (size_t i = 0; i < seeds.size(); ++i) {
    const EdgeSeed& s = seeds[i];
    EdgePoint point{cv::Point2d(s.pixel) + s.offset * s.normal, s.normal, magnitudes[i]};
    // The facet zero crossing decides which pixel carries the point (one per row/column
    // crossing); the profile fit then refines its position, which may leave the pixel by a
    // little on tight curves.
    if (!crossesInsidePixel(point, s.pixel)) continue;
    double bias = 0;
    if (params.fitProfile && fitsInImage(s.pixel, point) && fitsAt(s.pixel)) {
      EdgeProfileParams local = profile;
      local.halfAlong = profileHalfAlong(curvatures[i], profile);
      const auto refined = fitEdgeProfile(image, s.pixel, s.normal, s.offset, local);
      if (!refined) continue;
      point = *refined;
      bias = profileWindowBias(local);
    }
    result.points.push_back(point);
    pixels.push_back(s.pixel);
    windowBias.push_back(bias);
  }

  const bool link = params.linkContours || params.correctCurvatureBias || params.fitProfile;
  if (link) result.contours = linkEdgePoints(result.points, pixels);
  if (params.fitProfile) {
    // The straight-line fit returns the arc's mean offset over its window, kappa <t^2> / 2
    // towards the centre of curvature: remove it with the contour's curvature.
    // The curvature is shrunk by 0.001/px (r = 1000 px) so that the noise of straight contours'
    // curvature (~0.0006/px) does not move their points.
    const std::vector<double> kappa = contourCurvatures(result.points, result.contours, 8);
    for (size_t i = 0; i < result.points.size(); ++i) {
      const double k = std::copysign(std::max(0.0, std::abs(kappa[i]) - 0.001), kappa[i]);
      result.points[i].position += windowBias[i] * k * result.points[i].normal;
    }
  }
  if (params.correctCurvatureBias) {
    CurvatureBiasParams correction;
    correction.coefficient = curvatureBiasCoefficient(result.blurSigma);
    correctCurvatureBias(result.points, result.contours, correction);
  }
  if (params.fitProfile) dropPointsOutsideTheirPixel(result, pixels);
  if (!params.linkContours) result.contours.clear();
  return result;
}

}  // namespace facet
