// The caliper, line and blob steps on a rendered plate (plate_part.hpp), through recipe files as
// the line writes them: values in mm, and the bad inputs (outside the image, nothing to find, a
// wrong key) failing with their cause, never with a made-up value.
#include <cmath>
#include <sstream>

#include "algorithms/calibration/world_mapping.hpp"
#include "algorithms/circle/circle_measure.hpp"
#include "algorithms/geometry/pose2d.hpp"
#include "service/engine/frame_maps.hpp"
#include "service/engine/steps/placed_rect.hpp"
#include "tests/engine/plate_part.hpp"
#include "tests/support/scene/plane_scene.hpp"

namespace facet::service {
namespace {

namespace fs = std::filesystem;
using plate::value;

class MeasuringSteps : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = fs::temp_directory_path() / ("facet-measuring-" + std::to_string(::getpid()));
  }
  void TearDown() override { fs::remove_all(dir_); }
  InspectionOutcome inspect(const std::string& steps, const cv::Mat& image = plate::render()) {
    return plate::inspect(dir_, steps, image);
  }
  // The overlay's outline of a rim: its one polygon of 72 points.
  static std::vector<cv::Point2d> rimOutline(const InspectionOutcome& out) {
    for (const auto& s : out.overlay.shapes)
      if (s.kind == OverlayShape::Kind::Polygon && s.points.size() == 72) return s.points;
    return {};
  }
  static bool labelSays(const InspectionOutcome& out, const std::string& words) {
    for (const auto& s : out.overlay.shapes)
      if (s.kind == OverlayShape::Kind::Label && s.text.find(words) != std::string::npos)
        return true;
    return false;
  }
  fs::path dir_;
};

// A caliper across the plate, measuring its width as a pair of edges.
const std::string kAcrossCaliper = R"(  - id: across
    kind: caliper
    centre: [320, 240]
    length: 300
    width: 10
    measure: pairs
    polarity: rising
)";

TEST_F(MeasuringSteps, CaliperPairGivesThePlatesWidth) {
  const auto out = inspect(kAcrossCaliper + R"(    checks:
      width: {nominal: 12, tol_minus: 0.01, tol_plus: 0.01}
      position: {nominal: 0, tol_minus: 0.01, tol_plus: 0.01}
      count: {nominal: 1, tol_minus: 0, tol_plus: 0}
)");
  ASSERT_EQ(out.verdict, Verdict::Pass) << plate::failures(out);
  EXPECT_NEAR(value(out, "across.width").value, 12.0, 0.002);
  EXPECT_EQ(value(out, "across.width").unit, "mm");
}

TEST_F(MeasuringSteps, CaliperCountsRepeatedEdgesAndTheirSpacing) {
  const auto out = inspect(R"(  - id: slots
    kind: caliper
    centre: [320, 280]
    length: 60
    width: 10
    polarity: falling
    checks:
      count: {nominal: 3, tol_minus: 0, tol_plus: 0}
      spacing: {nominal: 1.0, tol_minus: 0.01, tol_plus: 0.01}
      position: {nominal: -1.15, tol_minus: 0.01, tol_plus: 0.01}
)");
  ASSERT_EQ(out.verdict, Verdict::Pass) << plate::failures(out);
  EXPECT_EQ(value(out, "slots.count").value, 3);
  EXPECT_NEAR(value(out, "slots.spacing").value, 1.0, 0.002);
}

TEST_F(MeasuringSteps, CaliperPartlyOutsideMeasuresInsideAndSaysSo) {
  const auto out = inspect(R"(  - id: edge
    kind: caliper
    centre: [100, 240]
    length: 600
    width: 10
    polarity: rising
    select: first
    checks:
      position: {nominal: 5, tol_minus: 0.01, tol_plus: 0.01, unit: mm}
)");
  ASSERT_EQ(out.verdict, Verdict::Pass) << plate::failures(out);
  EXPECT_NEAR(value(out, "edge.position").value, 5.0, 0.002);
  EXPECT_TRUE(labelSays(out, "outside the image"));
  // ... and in the part's record, for whoever reviews it without the picture.
  EXPECT_EQ(out.notes,
            std::vector<std::string>{
                "edge: part of the caliper lies outside the image: measured inside only"});
}

// The plate photographed with twice the exposure: its light face reads 255. The caliper's edges
// lie beside clipped grey values, and the part's record says so.
TEST_F(MeasuringSteps, CaliperBesideClippedGreyValuesSaysSo) {
  cv::Mat overexposed;
  plate::render().convertTo(overexposed, CV_8U, 2.0);
  const auto out = inspect(kAcrossCaliper, overexposed);
  ASSERT_EQ(out.notes.size(), 1u) << plate::failures(out);
  EXPECT_NE(out.notes[0].find("the sensor clipped the grey values beside an edge"),
            std::string::npos)
      << out.notes[0];
  // The same plate exposed as usual: nothing said.
  EXPECT_TRUE(inspect(kAcrossCaliper).notes.empty());
}

// The bore (0.8 mm) in the plate photographed with twice the exposure (the plate reads 255):
// measured with the clip in the grey fit, within 0.005 mm, and the part's record says that the
// sensor clipped its rim. With four times the exposure the step's middle lies beyond the clip:
// the step either fails with the cause or, where its grey values also fit a sharper and smaller
// step, is measured with the same note in the record (the image alone cannot tell them apart).
TEST_F(MeasuringSteps, CircleOnAClippedRimIsFittedAsClippedAndSaysSo) {
  const std::string bore = R"(  - id: bore
    kind: circle
    centre: [260, 200]
    nominal_diameter: 0.8
    search_width: 0.2
    polarity: dark_inside
    checks:
      diameter: {nominal: 0.8, tol_minus: 0.005, tol_plus: 0.005}
)";
  cv::Mat twice, fourTimes;
  plate::render().convertTo(twice, CV_8U, 2.0);
  const auto out = inspect(bore, twice);
  ASSERT_EQ(out.verdict, Verdict::Pass) << plate::failures(out);
  ASSERT_EQ(out.notes.size(), 1u);
  EXPECT_NE(out.notes[0].find("the sensor clipped"), std::string::npos) << out.notes[0];
  plate::render().convertTo(fourTimes, CV_8U, 4.0, -100.0);
  const auto heavy = inspect(bore, fourTimes);
  const std::string said = plate::failures(heavy) + (heavy.notes.empty() ? "" : heavy.notes[0]);
  EXPECT_TRUE(said.find("the rim is clipped") != std::string::npos ||
              said.find("the sensor clipped") != std::string::npos)
      << said;
}

// The plate's top edge with twice the exposure: the line's points lie beside clipped grey
// values, and the part's record says how many.
TEST_F(MeasuringSteps, LineBesideClippedGreyValuesSaysSo) {
  const std::string top = R"(  - id: top
    kind: line
    centre: [320, 152]
    length: 200
    width: 16
)";
  cv::Mat overexposed;
  plate::render().convertTo(overexposed, CV_8U, 2.0);
  const auto out = inspect(top, overexposed);
  ASSERT_EQ(out.notes.size(), 1u) << plate::failures(out);
  EXPECT_NE(out.notes[0].find("of its points lie beside grey values the sensor clipped"),
            std::string::npos)
      << out.notes[0];
  EXPECT_TRUE(inspect(top).notes.empty());
}

TEST_F(MeasuringSteps, CaliperOutsideTheImageOrWithoutAnEdgeFailsWithTheCause) {
  const std::string check =
      "    checks:\n      position: {nominal: 0, tol_minus: 1, tol_plus: 1}\n";
  const auto outside = inspect(
      "  - id: c\n    kind: caliper\n    centre: [-200, -200]\n    length: 40\n    width: 10\n" +
      check);
  EXPECT_EQ(outside.verdict, Verdict::Fail);
  ASSERT_FALSE(outside.failedChecks.empty());
  EXPECT_NE(outside.failedChecks[0].find("c: caliper not measured: the caliper lies outside"),
            std::string::npos)
      << outside.failedChecks[0];
  EXPECT_TRUE(std::isnan(value(outside, "c.position").value));

  // Only a rising edge at x = 200 here: a falling one is not made up.
  const auto wrongPolarity = inspect(
      "  - id: c\n    kind: caliper\n    centre: [200, 240]\n    length: 40\n    width: 10\n"
      "    polarity: falling\n" +
      check);
  EXPECT_EQ(wrongPolarity.verdict, Verdict::Fail);
  EXPECT_NE(plate::failures(wrongPolarity).find("no edge"), std::string::npos)
      << plate::failures(wrongPolarity);
  EXPECT_TRUE(std::isnan(value(wrongPolarity, "c.position").value));

  const auto flat = inspect(
      "  - id: c\n    kind: caliper\n    centre: [400, 200]\n    length: 40\n    width: 10\n" +
      check);
  EXPECT_NE(plate::failures(flat).find("no contrast"), std::string::npos) << plate::failures(flat);
}

// An arc around the plate's corner (200, 150) crosses its left edge at -90 degrees and its top
// edge at 0, both radial there: the caliper finds them 90 degrees apart, and positions, pair
// widths and spacing are lengths along the arc (30 px * pi / 2 = 47.12 px = 2.356 mm).
TEST_F(MeasuringSteps, CaliperOnAnArcGivesTheRadialEdgesAndLengthsAlongIt) {
  const double quarter = 30 * CV_PI / 2 * plate::kMmPerPixel;
  const auto out = inspect(R"(  - id: corner
    kind: caliper
    centre: [200, 150]
    radius: 30
    start_angle: -135
    extent: 180
    width: 8
    checks:
      count: {nominal: 2, tol_minus: 0, tol_plus: 0}
      position: {nominal: -1.178, tol_minus: 0.01, tol_plus: 0.01}
      spacing: {nominal: 2.356, tol_minus: 0.01, tol_plus: 0.01}
  - id: corner_pair
    kind: caliper
    centre: [200, 150]
    radius: 30
    start_angle: -135
    extent: 180
    width: 8
    measure: pairs
    polarity: rising
    checks:
      width: {nominal: 2.356, tol_minus: 0.01, tol_plus: 0.01}
      position: {nominal: 0, tol_minus: 0.01, tol_plus: 0.01}
)");
  ASSERT_EQ(out.verdict, Verdict::Pass) << plate::failures(out);
  EXPECT_NEAR(value(out, "corner.position").value, -quarter / 2, 0.005);
  EXPECT_NEAR(value(out, "corner.spacing").value, quarter, 0.005);
  EXPECT_NEAR(value(out, "corner_pair.width").value, quarter, 0.005);
  EXPECT_NEAR(value(out, "corner_pair.position").value, 0.0, 0.005);

  // Clockwise from +45 degrees the part begins at the top edge (rising, dark to light, that
  // way), a quarter turn before the arc's middle.
  const auto back = inspect(R"(  - id: corner
    kind: caliper
    centre: [200, 150]
    radius: 30
    start_angle: 45
    extent: -180
    width: 8
    polarity: rising
    select: first
    checks:
      position: {nominal: -1.178, tol_minus: 0.01, tol_plus: 0.01}
)");
  ASSERT_EQ(back.verdict, Verdict::Pass) << plate::failures(back);
  EXPECT_NEAR(value(back, "corner.position").value, -quarter / 2, 0.005);
}

// A caliper is a rectangle or an arc: the keys of one with the other, or of neither, are
// refused where they stand.
TEST_F(MeasuringSteps, CaliperShapeKeysThatDoNotFitAreRefused) {
  const auto both = plate::load(dir_, R"(  - id: c
    kind: caliper
    centre: [320, 240]
    length: 40
    radius: 30
    extent: 90
    width: 10
)");
  EXPECT_FALSE(both.recipe);
  EXPECT_NE(both.diagnostics.text().find("plate.recipe.yaml:9:"), std::string::npos)
      << both.diagnostics.text();
  EXPECT_NE(both.diagnostics.text().find("exclude each other"), std::string::npos);
  const auto neither = plate::load(dir_, R"(  - id: c
    kind: caliper
    centre: [320, 240]
    width: 10
)");
  EXPECT_FALSE(neither.recipe);
  EXPECT_NE(neither.diagnostics.text().find("'length' (a rectangle) or 'radius' (an arc)"),
            std::string::npos)
      << neither.diagnostics.text();
  const auto mixed = plate::load(dir_, R"(  - id: c
    kind: caliper
    centre: [320, 240]
    radius: 30
    angle: 10
    width: 10
  - id: d
    kind: caliper
    centre: [320, 240]
    length: 40
    extent: 90
    width: 10
)");
  EXPECT_FALSE(mixed.recipe);
  const std::string text = mixed.diagnostics.text();
  EXPECT_NE(text.find("an arc begins at 'start_angle'"), std::string::npos) << text;
  EXPECT_NE(text.find("an arc needs 'extent'"), std::string::npos) << text;
  EXPECT_NE(text.find("plate.recipe.yaml:15:"), std::string::npos) << text;
  EXPECT_NE(text.find("'extent' needs 'radius'"), std::string::npos) << text;
}

TEST_F(MeasuringSteps, LineGivesAngleOffsetAndStraightness) {
  const auto out = inspect(R"(  - id: top
    kind: line
    centre: [320, 152]
    length: 200
    width: 16
    polarity: rising
    checks:
      angle: {nominal: 0, tol_minus: 0.05, tol_plus: 0.05, unit: deg}
      position: {nominal: -0.1, tol_minus: 0.005, tol_plus: 0.005}
      straightness: {nominal: 0, tol_minus: 0, tol_plus: 0.01}
      rms: {nominal: 0, tol_minus: 0, tol_plus: 0.005}
  - id: left
    kind: line
    centre: [202, 240]
    length: 150
    width: 16
    angle: 90
    polarity: rising
    checks:
      angle: {nominal: 90, tol_minus: 0.05, tol_plus: 0.05, unit: deg}
      position: {nominal: -2, tol_minus: 0.1, tol_plus: 0.1, unit: px}
)");
  ASSERT_EQ(out.verdict, Verdict::Pass) << plate::failures(out);
  EXPECT_NEAR(value(out, "top.position").value, -0.1, 0.002);
  EXPECT_NEAR(value(out, "left.angle").value, 90.0, 0.02);
}

TEST_F(MeasuringSteps, LineOutsideTheImageFails) {
  const auto out = inspect(R"(  - id: l
    kind: line
    centre: [900, 900]
    length: 100
    width: 10
    checks:
      straightness: {nominal: 0, tol_minus: 0, tol_plus: 0.01}
)");
  EXPECT_EQ(out.verdict, Verdict::Fail);
  EXPECT_NE(plate::failures(out).find("l: line not measured: the line rectangle lies outside"),
            std::string::npos)
      << plate::failures(out);
}

const std::string kBoreBlob = R"(  - id: bore
    kind: blob
    centre: [260, 200]
    length: 30
    width: 30
    polarity: dark
)";

TEST_F(MeasuringSteps, BlobFindsTheBoreWithItsArea) {
  const auto out = inspect(kBoreBlob + R"(    checks:
      presence: {nominal: 1, tol_minus: 0, tol_plus: 0}
      count: {nominal: 1, tol_minus: 0, tol_plus: 0}
      area: {nominal: 0.5027, tol_minus: 0.005, tol_plus: 0.005}
)");
  ASSERT_EQ(out.verdict, Verdict::Pass) << plate::failures(out);
  EXPECT_NEAR(value(out, "bore.area").value, 64 * CV_PI * 0.0025, 0.005);
  EXPECT_EQ(value(out, "bore.area").unit, "mm2");
}

TEST_F(MeasuringSteps, MissingBlobFailsWithTheCauseUnlessAbsenceIsChecked) {
  const auto required = inspect(kBoreBlob + R"(    checks:
      presence: {nominal: 1, tol_minus: 0, tol_plus: 0}
)",
                                plate::render(false));
  EXPECT_EQ(required.verdict, Verdict::Fail);
  EXPECT_NE(plate::failures(required).find("bore: no blob found"), std::string::npos)
      << plate::failures(required);
  EXPECT_TRUE(std::isnan(value(required, "bore.presence").value));

  const auto absence = inspect(kBoreBlob + R"(    required: false
    checks:
      presence: {nominal: 0, tol_minus: 0, tol_plus: 0}
)",
                               plate::render(false));
  EXPECT_EQ(absence.verdict, Verdict::Pass) << plate::failures(absence);
}

TEST_F(MeasuringSteps, RecipeCheckNamesFileAndLineOfABadField) {
  const auto loaded = plate::load(dir_, R"(  - id: c
    kind: caliper
    centre: [320, 240]
    length: 0
    width: 10
    checks:
      width: {nominal: 1, tol_minus: 0.1, tol_plus: 0.1}
)");
  EXPECT_FALSE(loaded.recipe);
  const std::string text = loaded.diagnostics.text();
  // length: 0 is line 8; a width check without pairs is line 11.
  EXPECT_NE(text.find("plate.recipe.yaml:8:"), std::string::npos) << text;
  EXPECT_NE(text.find("length"), std::string::npos) << text;
  EXPECT_NE(text.find("plate.recipe.yaml:11:"), std::string::npos) << text;
  EXPECT_NE(text.find("needs 'measure: pairs'"), std::string::npos) << text;
}

TEST_F(MeasuringSteps, BlobOutsideTheImageFails) {
  const auto out = inspect(R"(  - id: b
    kind: blob
    centre: [-100, 900]
    length: 30
    width: 30
    checks:
      count: {nominal: 1, tol_minus: 0, tol_plus: 0}
)");
  EXPECT_NE(plate::failures(out).find("b: blobs not searched: the blob region lies outside"),
            std::string::npos)
      << plate::failures(out);
}

// With a lens model and a measuring plane, values are measured in the plane, in mm; a check in
// px gets them back through the scale.
TEST_F(MeasuringSteps, InACalibratedPlaneValuesAreMillimetresThere) {
  const auto out = plate::inspect(dir_, R"(  - id: across
    kind: caliper
    centre: [320, 240]
    length: 300
    width: 10
    measure: pairs
    polarity: rising
    checks:
      width: {nominal: 12, tol_minus: 0.01, tol_plus: 0.01}
  - id: across_px
    kind: caliper
    centre: [320, 240]
    length: 300
    width: 10
    measure: pairs
    checks:
      width: {nominal: 240, tol_minus: 0.2, tol_plus: 0.2, unit: px}
  - id: top
    kind: line
    centre: [320, 152]
    length: 200
    width: 16
    checks:
      position: {nominal: -0.1, tol_minus: 0.005, tol_plus: 0.005}
      angle: {nominal: 0, tol_minus: 0.05, tol_plus: 0.05, unit: deg}
  - id: corner
    kind: caliper
    centre: [200, 150]
    radius: 30
    start_angle: -135
    extent: 180
    width: 8
    checks:
      spacing: {nominal: 2.356, tol_minus: 0.01, tol_plus: 0.01}
)" + kBoreBlob + R"(    checks:
      area: {nominal: 0.5027, tol_minus: 0.005, tol_plus: 0.005}
)",
                                  plate::render(), plate::straightPlane());
  ASSERT_EQ(out.verdict, Verdict::Pass) << plate::failures(out);
  EXPECT_NEAR(value(out, "across.width").value, 12.0, 0.002);
}

// A 640x480 camera with a distorting lens (k1 -0.15) 200 mm from a light plane tilted `tiltDeg`
// degrees; lens blur 0.7 px, noise 1.
scene::PlaneScene tiltedView(double tiltDeg) {
  scene::PlaneScene s;
  s.camera.size = {640, 480};
  s.camera.fx = s.camera.fy = 1200, s.camera.cx = 319.5, s.camera.cy = 239.5;
  s.camera.k1 = -0.15;
  s.placement = scene::lookAtPlane({22, 16}, 200, tiltDeg, 20, 5, s.camera);
  s.background = 200;
  s.lensBlurSigma = 0.7;
  s.noiseSigma = 1;
  return s;
}

// The view's own camera and plane as the station's calibration.
config::Calibration calibrationOf(const scene::PlaneScene& s) {
  config::Calibration calibration;
  calibration.mmPerPixel = 0.17;
  calibration.cameraMatrix = cv::Mat(s.camera.matrix());
  calibration.distortion = s.camera.distortion();
  calibration.imageSize = s.camera.size;
  calibration.plane = PlanePose{s.placement.rotation, s.placement.translationMm, 0.0};
  return calibration;
}

// The view's mapping into its plane, as the station's calibration gives it.
WorldMapping mappingOf(const scene::PlaneScene& s) {
  return {CameraModel{s.camera.matrix(), s.camera.distortion(), s.camera.size},
          *calibrationOf(s).plane};
}

// On a plane seen at 30 degrees through a distorting lens, the blob step measures its largest
// blob in the plane: its area there, and its centre (which a distance step relates) is the
// blob's centre in the plane, not the image centroid mapped (which fails the 0.01 mm check).
// A caliper pair across the same disc has its middle there too (halfway between the edges in
// the plane, not in the image). The circle's roundness is the rim's in the plane: in the image
// the round bore is an ellipse, 0.5 mm from round at the plane's scale.
TEST_F(MeasuringSteps, OnATiltedPlaneABlobsAreaAndCentreAreThePlanes) {
  scene::PlaneScene s = tiltedView(30);
  const cv::Point2d blobMm(12, 15), boreMm(35, 18);
  s.addDisc(blobMm, 8, 40);
  s.addDisc(boreMm, 4, 40);
  const config::Calibration calibration = calibrationOf(s);
  const cv::Point2d a = s.imageOf(blobMm), b = s.imageOf(boreMm);
  const cv::Point2d x = s.imageOf(blobMm + cv::Point2d(0.01, 0)) - a;
  std::ostringstream steps;
  steps << "  - id: blob\n    kind: blob\n    centre: [" << a.x << ", " << a.y << "]\n"
        << "    length: 130\n    width: 130\n    polarity: dark\n    checks:\n"
        << "      area: {nominal: 201.06, tol_minus: 0.4, tol_plus: 0.4}\n"
        << "  - id: bore\n    kind: circle\n    centre: [" << b.x << ", " << b.y << "]\n"
        << "    nominal_diameter: 8\n    search_width: 2\n    polarity: dark_inside\n"
        << "    checks:\n      roundness: {nominal: 0, tol_minus: 0, tol_plus: 0.05}\n"
        << "  - id: apart\n    kind: distance\n    measure: centre_to_centre\n"
        << "    from: blob\n    to: bore\n    checks:\n"
        << "      distance: {nominal: 23.195, tol_minus: 0.01, tol_plus: 0.01}\n"
        << "  - id: across\n    kind: caliper\n    centre: [" << a.x << ", " << a.y << "]\n"
        << "    angle: " << std::atan2(-x.y, x.x) * 180 / CV_PI << "\n"
        << "    length: 130\n    width: 4\n    measure: pairs\n    polarity: falling\n"
        << "    checks:\n      width: {nominal: 16, tol_minus: 0.03, tol_plus: 0.03}\n"
        << "  - id: across_apart\n    kind: distance\n    measure: centre_to_centre\n"
        << "    from: across\n    to: bore\n    checks:\n"
        << "      distance: {nominal: 23.195, tol_minus: 0.01, tol_plus: 0.01}\n";
  const auto out = plate::inspect(dir_, steps.str(), s.render(), calibration);
  ASSERT_EQ(out.verdict, Verdict::Pass) << plate::failures(out);
  EXPECT_NEAR(value(out, "blob.area").value, 64 * CV_PI, 0.002 * 64 * CV_PI);
  EXPECT_NEAR(value(out, "apart.distance").value, cv::norm(blobMm - boreMm), 0.005);
  EXPECT_NEAR(value(out, "across_apart.distance").value, cv::norm(blobMm - boreMm), 0.005);
}

// On a plane seen at 62 degrees a bore is an ellipse of 0.47 : 1 in the image: flatter than the
// image measures as an ellipse, and its 0.5 px band about a circle holds too little of the rim
// (checked below with the step's own parameters). The circle step judges the rim again in the
// plane, where it is round, and measures it there: its place within 0.005 mm.
TEST_F(MeasuringSteps, OnASteepViewACircleTheImageRefusesIsMeasuredInThePlane) {
  scene::PlaneScene s = tiltedView(62);
  const cv::Point2d boreMm(22, 16);
  s.addDisc(boreMm, 4, 40);
  const config::Calibration calibration = calibrationOf(s);
  const cv::Mat image = s.render();
  // The nominal centre 0.5 px off the bore's image, as a part placed by hand would be.
  const cv::Point2d b = s.imageOf(boreMm) + cv::Point2d(0.4, -0.3);
  const WorldMapping plane = mappingOf(s);
  CircleMeasureParams p;  // as the step sets them
  p.centre = b;
  p.radius = 4.0 / plane.mmPerPixelAt(b);
  p.width = 2.0 / plane.mmPerPixelAt(b);
  p.polarity = CirclePolarity::DarkToLight;
  const CircleMeasurement inImage = measureCircle(image, p);
  ASSERT_FALSE(inImage.status.ok()) << "the view no longer makes the image refuse the bore";
  std::ostringstream steps;
  steps << "  - id: bore\n    kind: circle\n    centre: [" << b.x << ", " << b.y << "]\n"
        << "    nominal_diameter: 8\n    search_width: 2\n    polarity: dark_inside\n"
        << "    checks:\n      x: {nominal: 0, tol_minus: 0.2, tol_plus: 0.2}\n"
        << "      y: {nominal: 0, tol_minus: 0.2, tol_plus: 0.2}\n"
        << "      diameter: {nominal: 8, tol_minus: 0.01, tol_plus: 0.01}\n";
  const auto out = plate::inspect(dir_, steps.str(), image, calibration);
  ASSERT_EQ(out.verdict, Verdict::Pass) << inImage.status.message << "\n" << plate::failures(out);
  const cv::Point2d nominal = plane.toPlane(b);
  EXPECT_NEAR(value(out, "bore.x").value, boreMm.x - nominal.x, 0.005);
  EXPECT_NEAR(value(out, "bore.y").value, boreMm.y - nominal.y, 0.005);
  EXPECT_NEAR(value(out, "bore.diameter").value, 8, 0.005);
  // The overlay draws the circle in the plane as the image shows it: on the rim's image.
  const std::vector<cv::Point2d> outline = rimOutline(out);
  ASSERT_EQ(outline.size(), 72u);
  for (int i = 0; i < 72; ++i) {
    const double t = 2 * CV_PI * i / 72;
    EXPECT_LT(
        cv::norm(outline[i] - s.imageOf(boreMm + 4.0 * cv::Point2d(std::cos(t), std::sin(t)))), 0.1)
        << i;
  }
}

// Without a plane calibration, a bore on a plane seen at 30 degrees is an ellipse in the image:
// the circle step gives the ellipse's centre (within a fifth of a pixel of the image of the
// bore's centre; as a circle it was more than a pixel off), the diameter of the circle of its
// area, and says that the rim is an ellipse.
TEST_F(MeasuringSteps, WithoutAPlaneATiltedBoreIsMeasuredAsItsEllipseAndSaysSo) {
  scene::PlaneScene s = tiltedView(30);
  const cv::Point2d boreMm(22, 16);
  s.addDisc(boreMm, 4, 40);
  const cv::Point2d b = s.imageOf(boreMm), nominal = b + cv::Point2d(0.4, -0.3);
  config::Calibration scale;
  scale.mmPerPixel = mappingOf(s).mmPerPixelAt(b);
  std::ostringstream steps;
  steps << "  - id: bore\n    kind: circle\n    centre: [" << nominal.x << ", " << nominal.y
        << "]\n    nominal_diameter: 8\n    search_width: 2\n    polarity: dark_inside\n"
        << "    checks:\n      x: {nominal: 0, tol_minus: 1, tol_plus: 1}\n"
        << "      y: {nominal: 0, tol_minus: 1, tol_plus: 1}\n"
        << "      diameter: {nominal: 8, tol_minus: 1, tol_plus: 1}\n";
  const auto out = plate::inspect(dir_, steps.str(), s.render(), scale);
  ASSERT_EQ(out.verdict, Verdict::Pass) << plate::failures(out);
  EXPECT_NEAR(value(out, "bore.x").value / scale.mmPerPixel, b.x - nominal.x, 0.2);
  EXPECT_NEAR(value(out, "bore.y").value / scale.mmPerPixel, b.y - nominal.y, 0.2);
  // The circle of the ellipse's area: at the plane's mean scale there (the square root of its
  // area ratio) the bore's true diameter.
  EXPECT_NEAR(value(out, "bore.diameter").value, 8, 0.01);
  ASSERT_EQ(out.notes.size(), 1u);
  EXPECT_NE(out.notes[0].find("the rim is an ellipse"), std::string::npos) << out.notes[0];
  // The overlay draws the ellipse: its outline's extent is the rim's image's.
  const std::vector<cv::Point2d> outline = rimOutline(out);
  ASSERT_EQ(outline.size(), 72u);
  std::vector<cv::Point2d> rim;
  for (int i = 0; i < 720; ++i)
    rim.push_back(s.imageOf(
        boreMm + 4.0 * cv::Point2d(std::cos(i * CV_PI / 360), std::sin(i * CV_PI / 360))));
  const auto extent = [](const std::vector<cv::Point2d>& pts) {
    cv::Vec4d e(pts[0].x, pts[0].y, pts[0].x, pts[0].y);  // left, top, right, bottom
    for (const cv::Point2d& p : pts)
      e = {std::min(e[0], p.x), std::min(e[1], p.y), std::max(e[2], p.x), std::max(e[3], p.y)};
    return e;
  };
  const cv::Vec4d drawn = extent(outline), truth = extent(rim);
  for (int k = 0; k < 4; ++k) EXPECT_NEAR(drawn[k], truth[k], 0.3) << k;
}

// Round marks on a plane seen at 30 degrees are ellipses in the image, and an ellipse's centre is
// not the image of the circle's centre (checked below: a tenth of a pixel, 0.02 mm at this
// scale); measured as circles, the marks would be more than a pixel off. The fiducials step
// measures each mark in the plane: with the nominal marks at the images of the true centres, the
// marks' spacing and the pose's offset are within 0.003 mm of the truth.
TEST_F(MeasuringSteps, OnATiltedPlaneFiducialMarksAreMeasuredInThePlane) {
  scene::PlaneScene s = tiltedView(30);
  const cv::Point2d aMm(12, 9), bMm(32, 23);
  s.addDisc(aMm, 3, 40);
  s.addDisc(bMm, 3, 40);
  const config::Calibration calibration = calibrationOf(s);
  const cv::Mat image = s.render();
  const cv::Point2d a = s.imageOf(aMm), b = s.imageOf(bMm);
  const WorldMapping plane = mappingOf(s);
  // The image's own centres, px from the image of the mark's centre: as ellipses, as circles.
  double worst = 0, worstAsCircle = 0;
  for (const cv::Point2d& c : {a, b}) {
    CircleMeasureParams p;
    p.centre = c;
    p.radius = 3.0 / plane.mmPerPixelAt(c);
    p.width = 0.35 * p.radius;
    p.polarity = CirclePolarity::DarkToLight;
    const CircleMeasurement m = measureCircle(image, p);
    ASSERT_TRUE(m.status.ok()) << m.status.message;
    EXPECT_TRUE(m.elliptic);
    worst = std::max(worst, cv::norm(m.centre - c));
    p.measureEllipticRims = false;
    const CircleMeasurement round = measureCircle(image, p);
    ASSERT_TRUE(round.status.ok()) << round.status.message;
    worstAsCircle = std::max(worstAsCircle, cv::norm(round.centre - c));
  }
  ASSERT_GT(worst, 0.05) << "the view no longer moves the ellipse's centre off the mark's centre";
  EXPECT_GT(worstAsCircle, 1.0);
  const double spacing = cv::norm(bMm - aMm);
  std::ostringstream steps;
  steps << "  - id: marks\n    kind: fiducials\n    marks: [[" << a.x << ", " << a.y << "], ["
        << b.x << ", " << b.y << "]]\n    mark_diameter: 6\n    search_radius: 2\n"
        << "    polarity: dark_inside\n    checks:\n"
        << "      x: {nominal: 0, tol_minus: 0.003, tol_plus: 0.003}\n"
        << "      y: {nominal: 0, tol_minus: 0.003, tol_plus: 0.003}\n"
        << "      spacing: {nominal: " << spacing << ", tol_minus: 0.003, tol_plus: 0.003}\n";
  const auto out = plate::inspect(dir_, steps.str(), image, calibration);
  ASSERT_EQ(out.verdict, Verdict::Pass) << plate::failures(out);
  EXPECT_NEAR(value(out, "marks.spacing").value, spacing, 0.003);
  EXPECT_EQ(value(out, "marks.spacing").unit, "mm");
}

// An arc relative to a pose step follows it too: centre mapped, start turned, radius scaled.
TEST(PlacedArc, FollowsThePose) {
  const Pose2D pose{300, 200, radians(30), 2.0};
  const MeasuringArc a = placeArc(poseMap(pose, {10, 10}), {20, 10}, 15, -20, 90, 6);
  EXPECT_NEAR(a.cx, 300 + 20 * std::cos(radians(30)), 1e-9);
  EXPECT_NEAR(a.cy, 200 - 20 * std::sin(radians(30)), 1e-9);
  EXPECT_NEAR(a.radius, 30, 1e-9);
  EXPECT_NEAR(a.width, 12, 1e-9);
  EXPECT_NEAR(a.startAngle, 10, 1e-9);
  EXPECT_NEAR(a.extent, 90, 1e-9);
  const auto outline = arcOutline(a);
  ASSERT_GE(outline.size(), 4u);
  EXPECT_NEAR(cv::norm(outline.front() - cv::Point2d(a.cx, a.cy)), 36, 1e-9);
  EXPECT_NEAR(cv::norm(outline.back() - cv::Point2d(a.cx, a.cy)), 24, 1e-9);
}

// A rectangle relative to a pose step follows its pose: centre mapped, axis turned, sizes scaled.
TEST(PlacedRect, FollowsThePose) {
  const Pose2D pose{300, 200, radians(30), 2.0};
  const MeasuringRect r = placeRect(poseMap(pose, {10, 10}), {20, 10}, 40, 10, 15);
  EXPECT_NEAR(r.cx, 300 + 20 * std::cos(radians(30)), 1e-9);
  EXPECT_NEAR(r.cy, 200 - 20 * std::sin(radians(30)), 1e-9);
  EXPECT_NEAR(r.length, 80, 1e-9);
  EXPECT_NEAR(r.width, 20, 1e-9);
  EXPECT_NEAR(r.angle, 45, 1e-9);
  EXPECT_TRUE(
      insideRect(r, {r.cx + 39 * std::cos(radians(45)), r.cy - 39 * std::sin(radians(45))}));
  EXPECT_FALSE(
      insideRect(r, {r.cx + 41 * std::cos(radians(45)), r.cy - 41 * std::sin(radians(45))}));
}

}  // namespace
}  // namespace facet::service
