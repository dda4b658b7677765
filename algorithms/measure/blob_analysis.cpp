#include "algorithms/measure/blob_analysis.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>

#include <opencv2/imgproc.hpp>

namespace facet {
namespace {

BlobResult failed(MeasureFailure cause, std::string message, bool partial) {
  BlobResult r;
  r.status = Status<MeasureFailure>::failed(cause, std::move(message));
  r.partial = partial;
  return r;
}

double medianOf(std::vector<double>& v) {
  if (v.empty()) return 0;
  const auto mid = v.begin() + static_cast<std::ptrdiff_t>(v.size() / 2);
  std::nth_element(v.begin(), mid, v.end());
  return *mid;
}

// Weighted moments of one blob: area, centroid, ellipse.
struct Moments {
  double m00 = 0, m10 = 0, m01 = 0, m20 = 0, m11 = 0, m02 = 0;
  void add(double w, double x, double y) {
    m00 += w, m10 += w * x, m01 += w * y, m20 += w * x * x, m11 += w * x * y, m02 += w * y * y;
  }
};

void describe(const Moments& mo, cv::Point offset, Blob& b) {
  b.area = mo.m00;
  if (mo.m00 <= 0) return;
  const double cx = mo.m10 / mo.m00, cy = mo.m01 / mo.m00;
  b.centroid = {cx + offset.x, cy + offset.y};
  const double sxx = mo.m20 / mo.m00 - cx * cx, syy = mo.m02 / mo.m00 - cy * cy;
  const double sxy = mo.m11 / mo.m00 - cx * cy;
  const double mean = 0.5 * (sxx + syy);
  const double diff = std::sqrt(0.25 * (sxx - syy) * (sxx - syy) + sxy * sxy);
  // A uniform ellipse of semi-axis r has variance r^2 / 4 along it.
  b.majorRadius = 2.0 * std::sqrt(std::max(0.0, mean + diff));
  b.minorRadius = 2.0 * std::sqrt(std::max(0.0, mean - diff));
  // Grey weights spread the blob by the blur (each variance grows by sigma^2): scale the ellipse
  // to the blob's area, which the blur conserves (exact for discs).
  if (const double ellipseArea = CV_PI * b.majorRadius * b.minorRadius; ellipseArea > 0) {
    const double k = std::sqrt(b.area / ellipseArea);
    b.majorRadius *= k, b.minorRadius *= k;
  }
  double a = -0.5 * std::atan2(2 * sxy, sxx - syy) * 180.0 / CV_PI;  // y down: negate
  if (a <= -90) a += 180;
  b.angle = a;
}

// Grey on the 8-bit scale at (x, y) of an 8-bit or 16-bit image.
double greyAt(const cv::Mat& image, int x, int y) {
  return image.depth() == CV_8U ? image.at<uchar>(y, x) : image.at<ushort>(y, x) / 256.0;
}

// Grey-value area of component `label` of the region `grey` (the image's clipped region, read in
// place: converting a whole frame to doubles cost more than the labelling), see the header.
// `coverage` non-null: the weights are kept there too (region coordinates).
Moments greyMoments(const cv::Mat& grey, const cv::Mat& labels, int label, cv::Rect box, bool light,
                    BlobCoverage* coverage) {
  const int reach = 4;  // pixels: blur of sigma ~1.3 has faded below 0.1% of the step here
  const cv::Rect area =
      (box + cv::Size(2 * (reach + 2), 2 * (reach + 2)) - cv::Point(reach + 2, reach + 2)) &
      cv::Rect(0, 0, grey.cols, grey.rows);
  const cv::Mat mask = labels(area) == label;
  cv::Mat core, band, ringOuter;
  const cv::Mat k3 = cv::getStructuringElement(cv::MORPH_ELLIPSE, {5, 5});
  // The core lies 3 px inside the threshold line, where a step of blur sigma ~1 has reached
  // 99.9% of the object's grey; 2 px (98%) biased the object level of small blobs.
  cv::erode(mask, core, cv::getStructuringElement(cv::MORPH_ELLIPSE, {7, 7}), {-1, -1}, 1,
            cv::BORDER_CONSTANT, 0);
  cv::dilate(mask, band, k3, {-1, -1}, 2, cv::BORDER_CONSTANT, 0);
  cv::dilate(band, ringOuter, k3, {-1, -1}, 1, cv::BORDER_CONSTANT, 0);
  const cv::Mat others = (labels(area) != label) & (labels(area) != 0);
  std::vector<double> inside, outside, all;
  for (int r = 0; r < area.height; ++r) {
    for (int c = 0; c < area.width; ++c) {
      const double g = greyAt(grey, area.x + c, area.y + r);
      if (mask.at<uchar>(r, c)) all.push_back(g);
      if (core.at<uchar>(r, c)) inside.push_back(g);
      if (ringOuter.at<uchar>(r, c) && !band.at<uchar>(r, c) && !others.at<uchar>(r, c))
        outside.push_back(g);
    }
  }
  // A blob too small for a core: its brightest (light) or darkest pixel stands for the object.
  const double object = !inside.empty() ? medianOf(inside)
                        : light         ? *std::max_element(all.begin(), all.end())
                                        : *std::min_element(all.begin(), all.end());
  const double background = medianOf(outside);
  Moments mo;
  const double contrast = object - background;
  if (std::abs(contrast) < 1e-9) return mo;
  if (coverage) *coverage = {area, cv::Mat1f::zeros(area.size())};
  for (int r = 0; r < area.height; ++r) {
    for (int c = 0; c < area.width; ++c) {
      if (others.at<uchar>(r, c) || !band.at<uchar>(r, c)) continue;
      // The core counts as whole object; clamping its noise would bias the area down.
      const double w = core.at<uchar>(r, c)
                           ? 1.0
                           : (greyAt(grey, area.x + c, area.y + r) - background) / contrast;
      mo.add(w, c + area.x - box.x, r + area.y - box.y);
      if (coverage) coverage->share(r, c) = static_cast<float>(w);
    }
  }
  return mo;
}

}  // namespace

BlobResult analyseBlobs(const cv::Mat& image, const BlobParams& params) {
  if (image.type() != CV_8UC1 && image.type() != CV_16UC1)
    throw std::invalid_argument("blob: the image must be 8-bit or 16-bit grey");
  cv::Rect roi = params.roi.area() > 0 ? params.roi : cv::Rect(0, 0, image.cols, image.rows);
  if (params.roi.width < 0 || params.roi.height < 0 ||
      (params.roi.area() == 0 && params.roi != cv::Rect()))
    return failed(MeasureFailure::ZeroSize, "the blob region has zero size", false);
  const cv::Rect clipped = roi & cv::Rect(0, 0, image.cols, image.rows);
  if (clipped.area() == 0)
    return failed(MeasureFailure::OutsideImage, "the blob region lies outside the image", true);
  const bool partial = clipped != roi;
  const bool light = params.polarity == BlobPolarity::Light;

  cv::Mat grey8;
  if (image.depth() == CV_8U)
    grey8 = image(clipped);
  else
    image(clipped).convertTo(grey8, CV_8U, 1.0 / 256.0);
  double lo = 0, hi = 0;
  cv::minMaxLoc(grey8, &lo, &hi);
  if (hi - lo < params.minContrast)
    return failed(MeasureFailure::NoContrast,
                  "no contrast in the blob region: grey values span " + std::to_string(hi - lo),
                  partial);

  BlobResult result;
  result.partial = partial;
  cv::Mat binary;
  const int side = light ? cv::THRESH_BINARY : cv::THRESH_BINARY_INV;
  if (params.mode == BlobThreshold::Otsu) {
    result.threshold = cv::threshold(grey8, binary, 0, 255, side | cv::THRESH_OTSU);
  } else if (params.mode == BlobThreshold::Fixed) {
    result.threshold = params.threshold;
  } else {
    // The median from the 256-bin histogram: no copy of the region.
    std::vector<long> histogram(256, 0);
    for (int r = 0; r < grey8.rows; ++r)
      for (const uchar* p = grey8.ptr<uchar>(r); p != grey8.ptr<uchar>(r) + grey8.cols; ++p)
        ++histogram[*p];
    long below = 0;
    int med = 0;
    while (med < 255 && 2 * (below + histogram[med]) < static_cast<long>(grey8.total()))
      below += histogram[med++];
    result.threshold = light ? med + params.threshold : med - params.threshold;
  }
  // Light blobs: grey > threshold; dark blobs: grey <= threshold (the two sides of one split).
  if (params.mode != BlobThreshold::Otsu) cv::threshold(grey8, binary, result.threshold, 255, side);

  cv::Mat labels, stats, centroids;
  const int n = cv::connectedComponentsWithStats(binary, labels, stats, centroids, 8, CV_32S);
  const cv::Mat grey = image(clipped);
  for (int i = 1; i < n; ++i) {
    Blob b;
    b.bbox = {stats.at<int>(i, cv::CC_STAT_LEFT), stats.at<int>(i, cv::CC_STAT_TOP),
              stats.at<int>(i, cv::CC_STAT_WIDTH), stats.at<int>(i, cv::CC_STAT_HEIGHT)};
    b.pixels = stats.at<int>(i, cv::CC_STAT_AREA);
    b.touchesBorder = b.bbox.x == 0 || b.bbox.y == 0 || b.bbox.br().x == clipped.width ||
                      b.bbox.br().y == clipped.height;
    // A quick pre-filter on the pixel count keeps noise specks from costing a grey-value pass.
    if (b.pixels < 0.5 * params.minArea || b.pixels > 2.0 * params.maxArea + 16) continue;
    Moments mo;
    BlobCoverage* coverage = params.keepCoverage ? &b.coverage : nullptr;
    if (params.greyArea && !b.touchesBorder) {
      mo = greyMoments(grey, labels, i, b.bbox, light, coverage);
    }
    if (mo.m00 <= 0) {
      mo = {};
      if (coverage) *coverage = {b.bbox, cv::Mat1f::zeros(b.bbox.size())};
      for (int r = b.bbox.y; r < b.bbox.br().y; ++r) {
        const int* row = labels.ptr<int>(r);
        for (int c = b.bbox.x; c < b.bbox.br().x; ++c) {
          if (row[c] != i) continue;
          mo.add(1.0, c - b.bbox.x, r - b.bbox.y);
          if (coverage) coverage->share(r - b.bbox.y, c - b.bbox.x) = 1.0F;
        }
      }
    }
    describe(mo, b.bbox.tl() + clipped.tl(), b);
    b.bbox += clipped.tl();
    if (coverage) coverage->box += clipped.tl();
    if (b.area < params.minArea || b.area > params.maxArea) continue;
    if (b.majorRadius > 0 && b.minorRadius / b.majorRadius < params.minRoundness) continue;
    result.blobs.push_back(b);
  }
  std::sort(result.blobs.begin(), result.blobs.end(),
            [](const Blob& x, const Blob& y) { return x.area > y.area; });
  if (result.blobs.empty())
    return failed(MeasureFailure::NoBlob, "no blob passes the threshold and the filters", partial);
  return result;
}

}  // namespace facet
