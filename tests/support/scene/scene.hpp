#pragma once
// Test-scene generator: grey-value scenes with exact subpixel ground truth.
//
// Shapes (filled polygons and discs) are painted in order with antialiased coverage: each pixel
// row is cut into `subrows` horizontal sub-scanlines (256 by default, i.e. 256x supersampling in
// y); along each sub-scanline the covered interval is exact, so the coverage of a pixel is an
// area average exact in x and sampled finely in y. Then come the illumination gradient, the
// Gaussian PSF, additive noise and quantisation to 8 or 16 bits.
//
// Two blur models (SceneSpec::blurModel):
//  - PixelGrid: the Gaussian is applied to the pixel-integrated image, as a discrete kernel (what
//    a blur filter run on a sampled image does).
//  - Lens: the Gaussian acts on the continuous scene before the pixel integrates it, as an
//    optical PSF does (lens_blur.hpp): the pixel value is the scene convolved with the Gaussian
//    and the unit pixel square.
//
// Coordinates follow the design: x right, y down, the centre of pixel (0,0) is (0,0), so pixel
// (i,j) covers [i-0.5, i+0.5] x [j-0.5, j+0.5].

#include <cstdint>
#include <filesystem>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>
#include <opencv2/core.hpp>

namespace facet::scene {

enum class BlurModel { PixelGrid, Lens };

struct SceneSpec {
  cv::Size size{640, 480};
  double background = 40.0;                    // grey of the empty scene, on the 8-bit scale
  double blurSigma = 0.0;                      // Gaussian PSF sigma, pixels (0 = none)
  BlurModel blurModel = BlurModel::PixelGrid;  // where the blur acts (see above)
  int lensSupersampling = 8;  // Lens: fine cells per pixel and axis for the scene's coverage
  double noiseSigma = 0.0;    // additive Gaussian noise, grey levels on the 8-bit scale
  cv::Point2d illuminationGradient{0.0, 0.0};  // grey levels added per pixel in x and y,
                                               // zero at the image centre
  int depth = CV_8U;                           // CV_8U or CV_16U (16-bit grey = 8-bit grey * 256)
  int subrows = 256;                           // sub-scanlines per pixel row
  std::uint64_t seed = 1;                      // noise and clutter
};

struct Primitive {
  enum class Kind { Polygon, Disc };
  Kind kind = Kind::Polygon;
  std::vector<cv::Point2d> vertices;  // Polygon: simple polygon, either orientation
  cv::Point2d centre;                 // Disc
  double radius = 0.0;                // Disc
  double grey = 0.0;                  // 8-bit scale
  std::string role = "object";        // object, hole, clutter, occluder: kept in the ground truth
};

class Scene {
 public:
  explicit Scene(SceneSpec spec);

  void addPolygon(std::vector<cv::Point2d> vertices, double grey, std::string role = "object");
  void addDisc(cv::Point2d centre, double radius, double grey, std::string role = "object");
  void add(Primitive primitive);

  // Adds `count` random triangles, quadrilaterals and discs of size [minSize, maxSize] pixels
  // whose bounding boxes avoid every rectangle in `keepOut`, with greys in [greyLow, greyHigh].
  void addClutter(int count, double minSize, double maxSize, const std::vector<cv::Rect2d>& keepOut,
                  double greyLow = 0.0, double greyHigh = 255.0);

  // Hides `share` (0..1) of the area of the axis-aligned box `region` behind an occluding strip
  // that enters from a random side; returns the occluder polygon (also added to the scene).
  std::vector<cv::Point2d> addOccluder(const cv::Rect2d& region, double share, double grey);

  // The final image in spec().depth.
  [[nodiscard]] cv::Mat render() const;
  // The noise-free, blur-free image as doubles on the 8-bit scale.
  [[nodiscard]] cv::Mat renderIdeal() const;

  // Ground truth: the spec, every primitive, and whatever callers put into annotations().
  [[nodiscard]] nlohmann::json groundTruth() const;
  nlohmann::json& annotations() { return annotations_; }

  // Writes the image (format from the extension) and its ground truth as `<image>.json`.
  void write(const std::filesystem::path& image) const;

  [[nodiscard]] const SceneSpec& spec() const { return spec_; }
  [[nodiscard]] const std::vector<Primitive>& primitives() const { return primitives_; }

 private:
  SceneSpec spec_;
  std::vector<Primitive> primitives_;
  nlohmann::json annotations_ = nlohmann::json::object();
  std::uint64_t clutterDraws_ = 0;
};

// Coverage (0..1) of one primitive over an image of `size`, as doubles.
cv::Mat renderCoverage(const Primitive& primitive, cv::Size size, int subrows = 256);
// The same over the pixels of `window` only (which may reach outside any image: the primitive
// is defined everywhere); element (r, c) is pixel (window.x + c, window.y + r).
cv::Mat renderCoverage(const Primitive& primitive, const cv::Rect& window, int subrows);
// The same into `coverage` (reallocated only when its size or type differs).
void renderCoverageInto(const Primitive& primitive, const cv::Rect& window, int subrows,
                        cv::Mat& coverage);

// The primitive in the coordinates of a grid `scale` times finer (pixel (i, j) of the image
// covers fine cells i*scale .. i*scale+scale-1 in x, likewise in y).
Primitive scaled(const Primitive& primitive, int scale);

const char* blurModelName(BlurModel model);

// The primitives painted in order (painter's algorithm on coverage) over the pixels of `window`
// of a grid `scale` times finer than the image, on `background`, as doubles on the 8-bit scale.
cv::Mat paintCoverage(const std::vector<Primitive>& primitives, const cv::Rect& window,
                      double background, int scale, int subrows);
void paintCoverageInto(const std::vector<Primitive>& primitives, const cv::Rect& window,
                       double background, int scale, int subrows, cv::Mat& image);

double polygonArea(const std::vector<cv::Point2d>& vertices);  // unsigned
cv::Point2d polygonCentroid(const std::vector<cv::Point2d>& vertices);

}  // namespace facet::scene
