// bench_plane_measures: the measuring tools in a tilted plane seen through a distorting lens,
// measured there (facet) against the image measurement carried into the plane at one point and
// one scale (the baseline, what facet did before and what a tool without a plane model does).
//
// Scenes: the calibration tests' camera (1280x1024, fx 1500, k1 -0.22, k2 0.08) 250 mm from a
// plane tilted 0-30 degrees about a random axis, a part at a random place: a dark disc of
// radius 6 mm (blob), a dark bar 20 mm wide (caliper pair), a dark hole of radius 5 mm (circle:
// centre, diameter, roundness; the baseline of centre and diameter is the rim's edge points
// fitted in the plane, what facet measured before its grey-value fit there),
// a straight dark edge 70 mm long 38 mm from the view's centre (line). Without the plane: the
// hole's image centre as the circle step gives it on an uncalibrated station (its defaults: an
// elliptic rim measured as its ellipse), against the least-squares ellipse through the exact
// image of the rim; baseline: the same measurement with the circle model alone. Exact pixel
// coverage, lens blur 0.7 px before pixel integration and none (the full run prints both), noise 2
// grey levels. The calibration is the renderer's own camera and plane, so the table measures the
// measuring, not a calibration (bench_calibration measures that).
//
// Nothing in the tools was fitted to these scenes (the blob's interpolation step is set by its
// error bound, the rest is geometry); the seeds are printed so that other draws can be run
// (--seed N).
//
// Usage: bench_plane_measures [--smoke] [--scenes N] [--seed N]
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <ctime>
#include <random>
#include <string>
#include <vector>

#include <opencv2/imgproc.hpp>

#include "algorithms/calibration/plane_blob.hpp"
#include "algorithms/calibration/plane_circle.hpp"
#include "algorithms/calibration/plane_measures.hpp"
#include "algorithms/measure/blob_analysis.hpp"
#include "algorithms/measure/caliper.hpp"
#include "algorithms/measure/line_measure.hpp"
#include "bench/scene_run_args.hpp"
#include "tests/calibration/calibration_scenes.hpp"
#include "tests/support/scene/plane_scene.hpp"

namespace {

using namespace facet;

// Thread CPU time, ms: the machine may be shared.
double cpuMs() {
  timespec t{};
  clock_gettime(CLOCK_THREAD_CPUTIME_ID, &t);
  return t.tv_sec * 1e3 + t.tv_nsec * 1e-6;
}

// Times per circle, ms: the image measurement, and the measurement in the plane after it.
std::vector<double> imageCircleMs, planeCircleMs;

double median(std::vector<double> v) {
  if (v.empty()) return NAN;
  std::nth_element(v.begin(), v.begin() + v.size() / 2, v.end());
  return v[v.size() / 2];
}

// Sums of squares of one quantity's errors, facet and baseline.
struct Errors {
  double facet = 0, baseline = 0;
  int n = 0;
  void add(double f, double b) { facet += f * f, baseline += b * b, ++n; }
  [[nodiscard]] double facetRms() const { return n ? std::sqrt(facet / n) : NAN; }
  [[nodiscard]] double baselineRms() const { return n ? std::sqrt(baseline / n) : NAN; }
};

struct TiltRow {
  Errors blobCentre, blobArea, pairMiddle, circleCentre, markCentre, circleDiameter, roundness,
      straightness, lineOffset, imageCentre;
  int imageCircleOnly = 0;  // holes the circle model refused and the image measured as ellipses
  int missed = 0;
  int notRefined = 0;  // circles measured by their edge points alone (no grey fit in the plane)
  // Circles the image refused as circles (the baseline measures nothing), measured in the plane,
  // and the largest centre error among them, mm.
  int planeOnly = 0;
  double planeOnlyWorst = 0;
};

// A rectangle centred on the image of `centreMm`, its axis along the image of the plane
// direction `dirMm` there, covering `halfMm` either side, `widthPx` across.
MeasuringRect rectAlong(const scene::PlaneScene& s, cv::Point2d centreMm, cv::Point2d dirMm,
                        double halfMm, double widthPx) {
  const cv::Point2d c = s.imageOf(centreMm);
  const cv::Point2d t = s.imageOf(centreMm + 0.01 * dirMm) - c;
  const double reach = std::max(cv::norm(s.imageOf(centreMm + halfMm * dirMm) - c),
                                cv::norm(s.imageOf(centreMm - halfMm * dirMm) - c));
  return {c.x, c.y, 2 * reach, widthPx, std::atan2(-t.y, t.x) * 180 / CV_PI};
}

bool inside(const scene::PlaneScene& s, cv::Point2d mm, double marginPx) {
  const cv::Point2d p = s.imageOf(mm);
  return p.x > marginPx && p.y > marginPx && p.x < s.camera.size.width - marginPx &&
         p.y < s.camera.size.height - marginPx;
}

void measureScene(double tilt, double lensBlur, std::uint64_t seed, TiltRow& row) {
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> unit(0, 1);
  scene::PlaneScene s;
  s.camera = test::testCamera();
  const cv::Point2d target(40 + 20 * unit(rng), 30 + 20 * unit(rng));
  s.placement = scene::lookAtPlane(target, 250, tilt, 360 * unit(rng), 360 * unit(rng), s.camera);
  s.background = 30;
  const cv::Point2d disc = target + cv::Point2d(-30, -18), bar = target + cv::Point2d(18, -18),
                    hole = target + cv::Point2d(-30, 20), edge = target + cv::Point2d(0, 38);
  const double discR = 6, holeR = 5, barHalf = 10, edgeSlope = 0.05;
  s.addPolygon({target + cv::Point2d(-70, -50), target + cv::Point2d(70, -50),
                target + cv::Point2d(70, 60), target + cv::Point2d(-70, 60)},
               210);
  s.addDisc(disc, discR, 40);
  s.addPolygon({bar + cv::Point2d(-barHalf, -7), bar + cv::Point2d(barHalf, -7),
                bar + cv::Point2d(barHalf, 7), bar + cv::Point2d(-barHalf, 7)},
               40);
  s.addDisc(hole, holeR, 40);
  const auto onEdge = [&](double dx) { return edge + cv::Point2d(dx, edgeSlope * dx); };
  s.addPolygon(
      {onEdge(-40), onEdge(40), target + cv::Point2d(40, 58), target + cv::Point2d(-40, 58)}, 40);
  for (const cv::Point2d& p : {disc, bar, hole, onEdge(-40), onEdge(40)})
    if (!inside(s, p, 60)) return;  // the part leaves the view at this placement: not drawn
  s.lensBlurSigma = lensBlur;
  s.noiseSigma = 2;
  s.seed = seed;
  const cv::Mat image = s.render();
  const WorldMapping plane(CameraModel{s.camera.matrix(), s.camera.distortion(), s.camera.size},
                           PlanePose{s.placement.rotation, s.placement.translationMm, 0.0});

  // Blob: the disc.
  {
    const cv::Point2d c = s.imageOf(disc);
    const double r = discR / plane.mmPerPixelAt(c) * 1.6;
    BlobParams p;
    p.roi = cv::Rect(cv::Point(int(c.x - r), int(c.y - r)), cv::Point(int(c.x + r), int(c.y + r)));
    p.polarity = BlobPolarity::Dark;
    p.keepCoverage = true;
    const BlobResult b = analyseBlobs(image, p);
    const auto q = b.status.ok() ? blobInPlane(b.blobs.front(), plane) : std::nullopt;
    if (!q) {
      ++row.missed;
    } else {
      const Blob& blob = b.blobs.front();
      const double scale = plane.mmPerPixelAt(blob.centroid);
      const double area = CV_PI * discR * discR;
      row.blobCentre.add(cv::norm(q->centreMm - disc),
                         cv::norm(plane.toPlane(blob.centroid) - disc));
      row.blobArea.add(100 * (q->areaMm2 / area - 1), 100 * (blob.area * scale * scale / area - 1));
    }
  }
  // Caliper pair: the bar, along the plane's x.
  {
    const MeasuringRect rect = rectAlong(s, bar, {1, 0}, barHalf + 4, 16);
    const MeasuringPath path(rect);
    CaliperParams p;
    p.polarity = EdgePolarity::Falling;
    p.pairs = true;
    const CaliperResult m = measureCaliper(image, path, p);
    if (!m.status.ok() || m.pairs.size() != 1) {
      ++row.missed;
    } else {
      const CaliperPair& pr = m.pairs.front();
      const double mid = midpointInPlane(path, &plane, pr.first.position, pr.second.position);
      row.pairMiddle.add(plane.toPlane(path.at(mid, 0)).x - bar.x,
                         plane.toPlane(pr.centre).x - bar.x);
    }
  }
  // Circle: the hole's roundness (round: 0).
  {
    const cv::Point2d c = s.imageOf(hole);
    CircleMeasureParams p;
    p.centre = c + cv::Point2d(0.6, -0.4);
    p.radius = holeR / plane.mmPerPixelAt(c);
    p.width = 0.35 * p.radius;
    p.polarity = CirclePolarity::DarkToLight;
    // As the circle step on a calibrated station: the image's edge points without its grey fit,
    // a rim the image refuses as a circle judged in the plane.
    CircleMeasureParams edgesOnly = p;
    edgesOnly.refineWithGreyValues = false;
    const double t0 = cpuMs();
    const CircleMeasurement m = measureCircle(image, edgesOnly);
    const double t1 = cpuMs();
    const auto w = measureCircleInPlane(image, m, p, plane).circle;
    const double t2 = cpuMs();
    imageCircleMs.push_back(t1 - t0);
    planeCircleMs.push_back(t2 - t1);
    // The baseline: the edge points of the image measurement with its grey fit (whose blur sets
    // their curvature bias), mapped into the plane.
    const CircleMeasurement inImage = measureCircle(image, p);
    const auto edges = circleInPlane(inImage, plane);
    if (w && !edges) {
      // Refused by the image as a circle (the baseline has nothing), measured in the plane.
      ++row.planeOnly;
      row.planeOnlyWorst = std::max(row.planeOnlyWorst, cv::norm(w->centreMm - hole));
    } else if (!w || !edges) {
      // The image fit looks for a circle: on a steep view the rim is an ellipse there.
      std::printf("circle not measured (tilt %.0f, seed %llu): %s\n", tilt,
                  static_cast<unsigned long long>(seed), m.status.message.c_str());
      ++row.missed;
    } else {
      row.circleCentre.add(cv::norm(w->centreMm - hole), cv::norm(edges->centreMm - hole));
      // A fiducial mark's centre, as the fiducials step takes it; baseline: the image circle's
      // centre mapped (what the step took before it measured marks in the plane).
      row.markCentre.add(cv::norm(w->centreMm - hole),
                         cv::norm(plane.toPlane(inImage.centre) - hole));
      row.circleDiameter.add(w->diameterMm - 2 * holeR, edges->diameterMm - 2 * holeR);
      row.notRefined += w->greyRefined ? 0 : 1;
      row.roundness.add(w->roundnessMm, m.roundness * plane.mmPerPixelAt(m.centre));
    }
  }
  // Without a plane: the hole's image centre, the circle step's defaults against the circle model
  // alone, from the true image ellipse's centre.
  {
    std::vector<cv::Point2f> rim;
    for (int k = 0; k < 720; ++k)
      rim.emplace_back(s.imageOf(
          hole + holeR * cv::Point2d(std::cos(k * CV_PI / 360), std::sin(k * CV_PI / 360))));
    const cv::Point2d truth = cv::fitEllipse(rim).center;
    CircleMeasureParams p;
    p.centre = s.imageOf(hole) + cv::Point2d(0.6, -0.4);
    p.radius = holeR / plane.mmPerPixelAt(p.centre);
    p.width = 0.35 * p.radius;
    p.polarity = CirclePolarity::DarkToLight;
    const CircleMeasurement m = measureCircle(image, p);
    p.measureEllipticRims = false;
    const CircleMeasurement round = measureCircle(image, p);
    if (!m.status.ok())
      ++row.missed;
    else if (!round.status.ok())
      ++row.imageCircleOnly;
    else
      row.imageCentre.add(cv::norm(m.centre - truth), cv::norm(round.centre - truth));
  }
  // Line: the straight edge (straightness 0; the rectangle centred on it: offset 0).
  {
    const cv::Point2d along = cv::Point2d(1, edgeSlope) / std::hypot(1.0, edgeSlope);
    const MeasuringRect rect = rectAlong(s, edge, along, 35, 30);
    const LineMeasurement m = measureLine(image, rect);
    LineMeasurement ends = m;  // the baseline: the image fit's ends carried into the plane
    ends.inliers.clear();
    const auto f = m.status.ok() ? lineInPlane(rect, m, &plane) : std::nullopt;
    const auto b = m.status.ok() ? lineInPlane(rect, ends, &plane) : std::nullopt;
    if (!f || !b) {
      ++row.missed;
    } else {
      row.straightness.add(f->straightness, b->straightness);
      row.lineOffset.add(f->offset, b->offset);
    }
  }
}

void printRow(const char* quantity, double tilt, const Errors& e) {
  std::printf("| %-34s | %4.0f | %3d | %10.4f | %12.4f | %6.2f |\n", quantity, tilt, e.n,
              e.facetRms(), e.baselineRms(), e.facetRms() / e.baselineRms());
}

}  // namespace

int main(int argc, char** argv) {
  const auto args = facet::bench::parseSceneRunArgs(argc, argv, "bench_plane_measures", 8, 1);
  if (!args) return 1;
  const auto [smoke, scenes, seed] = *args;
  std::setvbuf(stdout, nullptr, _IOLBF, 0);
  const std::vector<double> tilts =
      smoke ? std::vector<double>{25} : std::vector<double>{0, 10, 20, 30};
  // A lens's blur, and none (pixel integration alone: the sharpest image a sensor gives).
  const std::vector<double> blurs = smoke ? std::vector<double>{0.7} : std::vector<double>{0.7, 0};
  const struct {
    const char* name;
    Errors TiltRow::*errors;
  } quantities[] = {{"blob centre, mm", &TiltRow::blobCentre},
                    {"blob area, %", &TiltRow::blobArea},
                    {"caliper pair middle, mm", &TiltRow::pairMiddle},
                    {"circle centre, mm", &TiltRow::circleCentre},
                    {"mark centre (fiducials), mm", &TiltRow::markCentre},
                    {"circle diameter, mm", &TiltRow::circleDiameter},
                    {"circle roundness, mm", &TiltRow::roundness},
                    {"line straightness, mm", &TiltRow::straightness},
                    {"line offset, mm", &TiltRow::lineOffset},
                    {"image circle centre (no plane), px", &TiltRow::imageCentre}};
  int missed = 0, notRefined = 0;
  bool broken = false;
  for (const double blur : blurs) {
    std::printf(
        "\nbench_plane_measures: %d scenes per tilt, seeds %llu.., 1280x1024, lens blur %.1f px, "
        "noise 2; RMS errors (roundness and straightness: the value read, truth 0)\n",
        scenes, static_cast<unsigned long long>(seed), blur);
    std::vector<TiltRow> rows(tilts.size());
    for (std::size_t t = 0; t < tilts.size(); ++t) {
      for (int k = 0; k < scenes; ++k)
        measureScene(tilts[t], blur, seed * 1000 + t * 100 + static_cast<std::uint64_t>(k),
                     rows[t]);
      missed += rows[t].missed;
      notRefined += rows[t].notRefined;
      if (rows[t].imageCircleOnly > 0)
        std::printf("tilt %.0f: %d holes refused by the circle model, measured as ellipses\n",
                    tilts[t], rows[t].imageCircleOnly);
      if (rows[t].planeOnly > 0)
        std::printf(
            "tilt %.0f: %d circles refused by the image as circles, measured in the plane "
            "(centre within %.4f mm)\n",
            tilts[t], rows[t].planeOnly, rows[t].planeOnlyWorst);
    }
    std::printf("| %-34s | %4s | %3s | %10s | %12s | %6s |\n", "quantity", "tilt", "n", "facet",
                "baseline", "ratio");
    std::printf("|---|---|---|---|---|---|\n");
    for (const auto& q : quantities)
      for (std::size_t t = 0; t < tilts.size(); ++t) printRow(q.name, tilts[t], rows[t].*q.errors);
    for (const TiltRow& row : rows)
      for (const auto& q : quantities) broken = broken || (row.*q.errors).n == 0;
  }
  std::printf(
      "baseline: blob centroid mapped, area x scale^2 there; the image's halfway point "
      "mapped; the circle's edge points fitted in the plane (facet before its grey-value fit "
      "there); the image circle's centre mapped (a fiducial mark); image roundness and "
      "straightness x scale; the image line's ends mapped; the image circle without the "
      "ellipse\n");
  std::printf(
      "tool runs that measured nothing: %d; circles without the grey fit in the plane: %d\n",
      missed, notRefined);
  std::printf(
      "time per circle (hole of radius 5 mm, about 29 px; median thread CPU time): image "
      "measurement (edge points, as the circle step with a plane) %.2f ms, then in the plane "
      "%.2f ms\n",
      median(imageCircleMs), median(planeCircleMs));
  if (broken) return 2;  // a tool that never measures at some tilt is broken here
  return 0;
}
