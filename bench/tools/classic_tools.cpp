#include "bench/tools/classic_tools.hpp"

#include <cmath>

#include <opencv2/imgproc.hpp>

namespace facet::bench {

std::vector<ClassicEdge> classicCaliper(const cv::Mat& image, const MeasuringRect& rect,
                                        double sigma, double minDerivative) {
  const MeasuringPath path(rect);
  const int n = static_cast<int>(std::floor(rect.length)) + 1;
  const int lines = std::max(1, static_cast<int>(std::round(rect.width)));
  std::vector<float> profile(n, 0.f);
  cv::Mat mapX(lines, n, CV_32F), mapY(lines, n, CV_32F);
  const double s0 = -(n - 1) / 2.0;
  for (int k = 0; k < lines; ++k)
    for (int i = 0; i < n; ++i) {
      const cv::Point2d p = path.at(s0 + i, -rect.width / 2 + 0.5 + k);
      mapX.at<float>(k, i) = static_cast<float>(p.x);
      mapY.at<float>(k, i) = static_cast<float>(p.y);
    }
  cv::Mat samples;
  cv::remap(image, samples, mapX, mapY, cv::INTER_LINEAR, cv::BORDER_REPLICATE);
  cv::Mat mean;
  cv::reduce(samples, mean, 0, cv::REDUCE_AVG, CV_64F);
  // Gaussian derivative kernel, normalised to unit response on a unit ramp.
  const int r = static_cast<int>(std::ceil(3 * sigma));
  std::vector<double> w(r + 1);
  double norm = 0;
  for (int j = 1; j <= r; ++j)
    w[j] = j * std::exp(-0.5 * j * j / (sigma * sigma)), norm += 2 * j * w[j];
  std::vector<double> d(n, 0.0);
  const auto* m = mean.ptr<double>(0);
  for (int i = 0; i < n; ++i) {
    double s = 0;
    for (int j = 1; j <= r; ++j) s += w[j] * (m[std::min(n - 1, i + j)] - m[std::max(0, i - j)]);
    d[i] = s / norm;
  }
  std::vector<ClassicEdge> edges;
  for (int i = 1; i + 1 < n; ++i) {
    const double v = std::abs(d[i]);
    if (v < minDerivative || v < std::abs(d[i - 1]) || v <= std::abs(d[i + 1])) continue;
    const double l = std::abs(d[i - 1]), rr = std::abs(d[i + 1]);
    const double den = l - 2 * v + rr;
    const double off = den < 0 ? 0.5 * (l - rr) / den : 0.0;
    edges.push_back({s0 + i + off, d[i]});
  }
  return edges;
}

ClassicLine cannyFitLine(const cv::Mat& image, const MeasuringRect& rect) {
  cv::Mat edges;
  cv::Canny(image, edges, 30, 80, 3, true);
  const MeasuringPath path(rect);
  std::vector<cv::Point2f> pts;
  const cv::Point2d c(rect.cx, rect.cy), d = path.axisAt(0);
  const cv::Point2d across(-d.y, d.x);
  for (int y = 0; y < edges.rows; ++y)
    for (int x = 0; x < edges.cols; ++x) {
      if (!edges.at<uchar>(y, x)) continue;
      const cv::Point2d q = cv::Point2d(x, y) - c;
      if (std::abs(q.dot(d)) <= rect.length / 2 && std::abs(q.dot(across)) <= rect.width / 2)
        pts.emplace_back(static_cast<float>(x), static_cast<float>(y));
    }
  ClassicLine out;
  if (pts.size() < 2) return out;
  cv::Vec4f l;
  cv::fitLine(pts, l, cv::DIST_L2, 0, 0.01, 0.01);
  out.ok = true;
  out.direction = {l[0], l[1]};
  out.point = {l[2], l[3]};
  return out;
}

std::vector<ClassicBlob> otsuComponents(const cv::Mat& image) {
  cv::Mat binary, labels, stats, centroids;
  cv::threshold(image, binary, 0, 255, cv::THRESH_BINARY | cv::THRESH_OTSU);
  const int n = cv::connectedComponentsWithStats(binary, labels, stats, centroids, 8, CV_32S);
  std::vector<ClassicBlob> blobs;
  for (int i = 1; i < n; ++i)
    blobs.push_back({static_cast<double>(stats.at<int>(i, cv::CC_STAT_AREA)),
                     {centroids.at<double>(i, 0), centroids.at<double>(i, 1)}});
  return blobs;
}

}  // namespace facet::bench
