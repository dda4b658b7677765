// The distance step's relations between points and lines on the rendered plate
// (plate_part.hpp): a bore's distance from an edge (point-line), the distance and angle of the
// two parallel long edges (line-line), the corner where two edges cross (intersection) and its
// distance from the bore, the angle between two edges.
#include <cmath>

#include "tests/engine/plate_part.hpp"

namespace facet::service {
namespace {

namespace fs = std::filesystem;
using plate::value;

// The bore, the plate's top (y = 150), bottom (y = 330) and left (x = 200) edges.
const std::string kFeatures = R"(  - id: bore
    kind: circle
    centre: [260, 200]
    nominal_diameter: 0.8
    search_width: 0.2
    polarity: dark_inside
  - id: top
    kind: line
    centre: [320, 152]
    length: 200
    width: 16
  - id: bottom
    kind: line
    centre: [320, 328]
    length: 200
    width: 16
  - id: left
    kind: line
    centre: [202, 240]
    length: 150
    width: 16
    angle: 90
)";

class DistanceRelations : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = fs::temp_directory_path() / ("facet-relations-" + std::to_string(::getpid()));
  }
  void TearDown() override { fs::remove_all(dir_); }
  InspectionOutcome inspect(const std::string& relations) {
    return plate::inspect(dir_, kFeatures + relations, plate::render());
  }
  fs::path dir_;
};

TEST_F(DistanceRelations, PointToLine) {
  const auto out = inspect(R"(  - id: bore_to_top
    kind: distance
    measure: point_to_line
    from: bore
    to: top
    checks:
      distance: {nominal: 2.5, tol_minus: 0.01, tol_plus: 0.01}
)");
  ASSERT_EQ(out.verdict, Verdict::Pass) << plate::failures(out);
  EXPECT_NEAR(value(out, "bore_to_top.distance").value, 2.5, 0.003);
}

TEST_F(DistanceRelations, LineToLineGivesDistanceAndAngleOfParallelEdges) {
  const auto out = inspect(R"(  - id: height
    kind: distance
    measure: line_to_line
    from: top
    to: bottom
    checks:
      distance: {nominal: 9.0, tol_minus: 0.01, tol_plus: 0.01}
      angle: {nominal: 0, tol_minus: 0.05, tol_plus: 0.05, unit: deg}
)");
  ASSERT_EQ(out.verdict, Verdict::Pass) << plate::failures(out);
  EXPECT_NEAR(value(out, "height.distance").value, 9.0, 0.003);
  EXPECT_NEAR(value(out, "height.angle").value, 0.0, 0.02);
}

TEST_F(DistanceRelations, IntersectionIsAPointForLaterSteps) {
  const auto out = inspect(R"(  - id: corner
    kind: distance
    measure: intersection
    from: top
    to: left
    checks:
      angle: {nominal: 90, tol_minus: 0.05, tol_plus: 0.05, unit: deg}
  - id: corner_to_bore
    kind: distance
    measure: centre_to_centre
    from: corner
    to: bore
    checks:
      distance: {nominal: 3.9051, tol_minus: 0.01, tol_plus: 0.01}
)");
  ASSERT_EQ(out.verdict, Verdict::Pass) << plate::failures(out);
  EXPECT_NEAR(value(out, "corner_to_bore.distance").value, std::hypot(60, 50) * 0.05, 0.003);
}

TEST_F(DistanceRelations, ParallelLinesDoNotCross) {
  const auto out = inspect(R"(  - id: corner
    kind: distance
    measure: intersection
    from: top
    to: bottom
    checks:
      angle: {nominal: 0, tol_minus: 1, tol_plus: 1, unit: deg}
)");
  EXPECT_EQ(out.verdict, Verdict::Fail);
  EXPECT_NE(plate::failures(out).find("parallel"), std::string::npos) << plate::failures(out);
}

TEST_F(DistanceRelations, ACheckTheMeasureDoesNotGiveIsRefused) {
  const auto loaded = plate::load(dir_, kFeatures + R"(  - id: crossing
    kind: distance
    measure: intersection
    from: top
    to: left
    checks:
      distance: {nominal: 1, tol_minus: 0.1, tol_plus: 0.1}
)");
  EXPECT_FALSE(loaded.recipe);
  EXPECT_NE(loaded.diagnostics.text().find("does not fit measure 'intersection'"),
            std::string::npos)
      << loaded.diagnostics.text();
}

}  // namespace
}  // namespace facet::service
