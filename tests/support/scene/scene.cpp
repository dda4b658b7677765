#include "tests/support/scene/scene.hpp"

#include "tests/support/scene/lens_blur.hpp"

#include <algorithm>
#include <cmath>
#include <fstream>
#include <numbers>
#include <random>
#include <stdexcept>

#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

namespace facet::scene {
namespace {

cv::Rect2d boundingBox(const Primitive& p) {
  if (p.kind == Primitive::Kind::Disc)
    return {p.centre.x - p.radius, p.centre.y - p.radius, 2 * p.radius, 2 * p.radius};
  double x0 = 1e300, y0 = 1e300, x1 = -1e300, y1 = -1e300;
  for (const auto& v : p.vertices) {
    x0 = std::min(x0, v.x), y0 = std::min(y0, v.y);
    x1 = std::max(x1, v.x), y1 = std::max(y1, v.y);
  }
  return {x0, y0, x1 - x0, y1 - y0};
}

// Sorted x where the horizontal line at y enters and leaves the primitive.
void crossings(const Primitive& p, double y, std::vector<double>& xs) {
  xs.clear();
  if (p.kind == Primitive::Kind::Disc) {
    const double dy = y - p.centre.y;
    const double h2 = p.radius * p.radius - dy * dy;
    if (h2 > 0) {
      const double h = std::sqrt(h2);
      xs.push_back(p.centre.x - h);
      xs.push_back(p.centre.x + h);
    }
    return;
  }
  const auto& v = p.vertices;
  for (std::size_t i = 0, n = v.size(); i < n; ++i) {
    const cv::Point2d a = v[i], b = v[(i + 1) % n];
    // Half-open rule: a vertex exactly on the line is counted once.
    if ((a.y <= y) != (b.y <= y)) xs.push_back(a.x + (y - a.y) * (b.x - a.x) / (b.y - a.y));
  }
  std::sort(xs.begin(), xs.end());
}

// Adds weight w times the exact overlap of [x0, x1] with each pixel [i-0.5, i+0.5] of a row.
// Whole pixels go through the difference buffer `diff` (prefix-summed later).
void addSpan(double* row, double* diff, int width, double x0, double x1, double w) {
  x0 = std::max(x0, -0.5);
  x1 = std::min(x1, width - 0.5);
  if (x1 <= x0) return;
  const int i0 = std::clamp(static_cast<int>(std::floor(x0 + 0.5)), 0, width - 1);
  const int i1 = std::clamp(static_cast<int>(std::floor(x1 + 0.5)), 0, width - 1);
  if (i0 == i1) {
    row[i0] += w * (x1 - x0);
    return;
  }
  row[i0] += w * (i0 + 0.5 - x0);
  row[i1] += w * (x1 - (i1 - 0.5));
  diff[i0 + 1] += w;
  diff[i1] -= w;
}

}  // namespace

cv::Mat renderCoverage(const Primitive& primitive, cv::Size size, int subrows) {
  return renderCoverage(primitive, cv::Rect({0, 0}, size), subrows);
}

cv::Mat renderCoverage(const Primitive& primitive, const cv::Rect& window, int subrows) {
  cv::Mat coverage;
  renderCoverageInto(primitive, window, subrows, coverage);
  return coverage;
}

void renderCoverageInto(const Primitive& primitive, const cv::Rect& window, int subrows,
                        cv::Mat& coverage) {
  coverage.create(window.size(), CV_64F);
  coverage.setTo(0.0);
  const cv::Rect2d box = boundingBox(primitive);
  const int r0 = std::max(window.y, static_cast<int>(std::floor(box.y + 0.5)));
  const int r1 = std::min(window.y + window.height - 1,
                          static_cast<int>(std::floor(box.y + box.height + 0.5)));
  std::vector<double> xs, diff(static_cast<std::size_t>(window.width) + 1);
  const double w = 1.0 / subrows;
  // Spans are cut in window-local x: pixel window.x + c covers [c - 0.5, c + 0.5] there.
  const double shift = window.x;
  for (int r = r0; r <= r1; ++r) {
    auto* row = coverage.ptr<double>(r - window.y);
    std::fill(diff.begin(), diff.end(), 0.0);
    for (int k = 0; k < subrows; ++k) {
      const double y = r - 0.5 + (k + 0.5) * w;
      crossings(primitive, y, xs);
      for (std::size_t i = 0; i + 1 < xs.size(); i += 2)
        addSpan(row, diff.data(), window.width, xs[i] - shift, xs[i + 1] - shift, w);
    }
    double run = 0.0;
    for (int c = 0; c < window.width; ++c) {
      run += diff[static_cast<std::size_t>(c)];
      row[c] += run;
    }
  }
}

Primitive scaled(const Primitive& primitive, int scale) {
  Primitive p = primitive;
  const auto map = [scale](cv::Point2d q) {
    return (q + cv::Point2d(0.5, 0.5)) * scale - cv::Point2d(0.5, 0.5);
  };
  for (auto& v : p.vertices) v = map(v);
  p.centre = map(p.centre);
  p.radius *= scale;
  return p;
}

const char* blurModelName(BlurModel model) {
  return model == BlurModel::Lens ? "lens" : "pixel-grid";
}

double polygonArea(const std::vector<cv::Point2d>& v) {
  double a = 0.0;
  for (std::size_t i = 0, n = v.size(); i < n; ++i) a += v[i].cross(v[(i + 1) % n]);
  return std::abs(a) / 2.0;
}

cv::Point2d polygonCentroid(const std::vector<cv::Point2d>& v) {
  double a = 0.0, cx = 0.0, cy = 0.0;
  for (std::size_t i = 0, n = v.size(); i < n; ++i) {
    const cv::Point2d p = v[i], q = v[(i + 1) % n];
    const double c = p.cross(q);
    a += c;
    cx += (p.x + q.x) * c;
    cy += (p.y + q.y) * c;
  }
  return {cx / (3.0 * a), cy / (3.0 * a)};
}

Scene::Scene(SceneSpec spec) : spec_(spec) {
  if (spec_.depth != CV_8U && spec_.depth != CV_16U)
    throw std::invalid_argument("scene: depth must be CV_8U or CV_16U");
  if (spec_.subrows < 1) throw std::invalid_argument("scene: subrows must be >= 1");
  if (spec_.lensSupersampling < 1)
    throw std::invalid_argument("scene: lensSupersampling must be >= 1");
}

void Scene::add(Primitive primitive) {
  primitives_.push_back(std::move(primitive));
}

void Scene::addPolygon(std::vector<cv::Point2d> vertices, double grey, std::string role) {
  Primitive p;
  p.kind = Primitive::Kind::Polygon;
  p.vertices = std::move(vertices);
  p.grey = grey;
  p.role = std::move(role);
  add(std::move(p));
}

void Scene::addDisc(cv::Point2d centre, double radius, double grey, std::string role) {
  Primitive p;
  p.kind = Primitive::Kind::Disc;
  p.centre = centre;
  p.radius = radius;
  p.grey = grey;
  p.role = std::move(role);
  add(std::move(p));
}

void Scene::addClutter(int count, double minSize, double maxSize,
                       const std::vector<cv::Rect2d>& keepOut, double greyLow, double greyHigh) {
  std::mt19937_64 rng(spec_.seed * 7919 + ++clutterDraws_);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  const double w = spec_.size.width, h = spec_.size.height;
  int added = 0;
  for (int attempt = 0; added < count && attempt < count * 200; ++attempt) {
    const double size = minSize + (maxSize - minSize) * u(rng);
    const cv::Point2d c{size / 2 + u(rng) * (w - size), size / 2 + u(rng) * (h - size)};
    const cv::Rect2d box{c.x - size / 2 - 2, c.y - size / 2 - 2, size + 4, size + 4};
    if (std::any_of(keepOut.begin(), keepOut.end(),
                    [&](const cv::Rect2d& k) { return (k & box).area() > 0; }))
      continue;
    const double grey = greyLow + (greyHigh - greyLow) * u(rng);
    const int kind = static_cast<int>(u(rng) * 3);
    if (kind == 2) {
      addDisc(c, size / 2, grey, "clutter");
    } else {
      const int n = kind == 0 ? 3 : 4;
      const double phase = u(rng) * 2 * std::numbers::pi;
      std::vector<cv::Point2d> v;
      for (int i = 0; i < n; ++i) {
        const double a = phase + 2 * std::numbers::pi * (i + 0.3 * (u(rng) - 0.5)) / n;
        const double r = size / 2 * (0.6 + 0.4 * u(rng));
        v.push_back({c.x + r * std::cos(a), c.y + r * std::sin(a)});
      }
      addPolygon(std::move(v), grey, "clutter");
    }
    ++added;
  }
}

std::vector<cv::Point2d> Scene::addOccluder(const cv::Rect2d& region, double share, double grey) {
  std::mt19937_64 rng(spec_.seed * 104729 + ++clutterDraws_);
  const int side = static_cast<int>(std::uniform_int_distribution<int>(0, 3)(rng));
  const double m = 2.0;  // margin so the strip's far edges lie outside the region
  const double x0 = region.x - m, y0 = region.y - m;
  const double x1 = region.x + region.width + m, y1 = region.y + region.height + m;
  std::vector<cv::Point2d> v;
  switch (side) {
    case 0: {  // from the left
      const double xe = region.x + share * region.width;
      v = {{x0, y0}, {xe, y0}, {xe, y1}, {x0, y1}};
      break;
    }
    case 1: {  // from the right
      const double xs = region.x + (1 - share) * region.width;
      v = {{xs, y0}, {x1, y0}, {x1, y1}, {xs, y1}};
      break;
    }
    case 2: {  // from the top
      const double ye = region.y + share * region.height;
      v = {{x0, y0}, {x1, y0}, {x1, ye}, {x0, ye}};
      break;
    }
    default: {  // from the bottom
      const double ys = region.y + (1 - share) * region.height;
      v = {{x0, ys}, {x1, ys}, {x1, y1}, {x0, y1}};
      break;
    }
  }
  addPolygon(v, grey, "occluder");
  return v;
}

cv::Mat Scene::renderIdeal() const {
  return paintCoverage(primitives_, cv::Rect({0, 0}, spec_.size), spec_.background, 1,
                       spec_.subrows);
}

cv::Mat paintCoverage(const std::vector<Primitive>& primitives, const cv::Rect& window,
                      double background, int scale, int subrows) {
  cv::Mat image;
  paintCoverageInto(primitives, window, background, scale, subrows, image);
  return image;
}

void paintCoverageInto(const std::vector<Primitive>& primitives, const cv::Rect& window,
                       double background, int scale, int subrows, cv::Mat& image) {
  image.create(window.size(), CV_64F);
  image.setTo(background);
  thread_local cv::Mat cov;  // reused: large buffers cost more in page faults than in filling
  for (const Primitive& primitive : primitives) {
    const Primitive p = scale == 1 ? primitive : scaled(primitive, scale);
    const cv::Rect2d b = boundingBox(p);
    const cv::Rect box = cv::Rect(cv::Point(static_cast<int>(std::floor(b.x - 1)),
                                            static_cast<int>(std::floor(b.y - 1))),
                                  cv::Point(static_cast<int>(std::ceil(b.x + b.width + 2)),
                                            static_cast<int>(std::ceil(b.y + b.height + 2)))) &
                         window;
    if (box.empty()) continue;
    renderCoverageInto(p, box, subrows, cov);
    // Painter's algorithm on coverage: image = image * (1 - c) + grey * c.
    cv::Mat part = image(box - window.tl());
    for (int r = 0; r < cov.rows; ++r) {
      const auto* c = cov.ptr<double>(r);
      auto* v = part.ptr<double>(r);
      for (int x = 0; x < cov.cols; ++x)
        if (c[x] != 0.0) v[x] += c[x] * (p.grey - v[x]);
    }
  }
}

cv::Mat Scene::render() const {
  const bool lens = spec_.blurModel == BlurModel::Lens && spec_.blurSigma > 0.0;
  cv::Mat image = lens ? renderLensBlurred(primitives_, spec_) : renderIdeal();
  const auto [gx, gy] = spec_.illuminationGradient;
  if (gx != 0.0 || gy != 0.0) {
    const double cx = (spec_.size.width - 1) / 2.0, cy = (spec_.size.height - 1) / 2.0;
    for (int r = 0; r < image.rows; ++r) {
      auto* row = image.ptr<double>(r);
      for (int c = 0; c < image.cols; ++c) row[c] += gx * (c - cx) + gy * (r - cy);
    }
  }
  if (spec_.blurSigma > 0.0 && !lens) {
    const int k = 2 * static_cast<int>(std::ceil(4.0 * spec_.blurSigma)) + 1;
    cv::GaussianBlur(image, image, cv::Size(k, k), spec_.blurSigma, spec_.blurSigma,
                     cv::BORDER_REFLECT);
  }
  if (spec_.noiseSigma > 0.0) {
    std::mt19937_64 rng(spec_.seed);
    std::normal_distribution<double> n(0.0, spec_.noiseSigma);
    for (int r = 0; r < image.rows; ++r) {
      auto* row = image.ptr<double>(r);
      for (int c = 0; c < image.cols; ++c) row[c] += n(rng);
    }
  }
  cv::Mat out;
  if (spec_.depth == CV_8U)
    image.convertTo(out, CV_8U);  // rounds and saturates
  else
    image.convertTo(out, CV_16U, 256.0);
  return out;
}

nlohmann::json Scene::groundTruth() const {
  nlohmann::json prims = nlohmann::json::array();
  for (const Primitive& p : primitives_) {
    nlohmann::json j{{"role", p.role}, {"grey", p.grey}};
    if (p.kind == Primitive::Kind::Disc) {
      j["kind"] = "disc";
      j["centre"] = {p.centre.x, p.centre.y};
      j["radius"] = p.radius;
    } else {
      j["kind"] = "polygon";
      nlohmann::json v = nlohmann::json::array();
      for (const auto& q : p.vertices) v.push_back({q.x, q.y});
      j["vertices"] = v;
    }
    prims.push_back(j);
  }
  return {{"spec",
           {{"width", spec_.size.width},
            {"height", spec_.size.height},
            {"background", spec_.background},
            {"blur_sigma", spec_.blurSigma},
            {"blur_model", blurModelName(spec_.blurModel)},
            {"lens_supersampling", spec_.lensSupersampling},
            {"noise_sigma", spec_.noiseSigma},
            {"illumination_gradient", {spec_.illuminationGradient.x, spec_.illuminationGradient.y}},
            {"bits", spec_.depth == CV_8U ? 8 : 16},
            {"subrows", spec_.subrows},
            {"seed", spec_.seed}}},
          {"primitives", prims},
          {"annotations", annotations_}};
}

void Scene::write(const std::filesystem::path& image) const {
  if (!image.parent_path().empty()) std::filesystem::create_directories(image.parent_path());
  if (!cv::imwrite(image.string(), render()))
    throw std::runtime_error("scene: cannot write " + image.string());
  std::ofstream json(image.string() + ".json");
  json << groundTruth().dump(2) << "\n";
  if (!json) throw std::runtime_error("scene: cannot write " + image.string() + ".json");
}

}  // namespace facet::scene
