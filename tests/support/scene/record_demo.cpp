// record_demo: regenerates the example recipes' reference images, templates and recorded demo
// folders (recipes/models, recipes/demo) deterministically with the scene generator.
//
//   record_demo [RECIPES_FOLDER]      (default: <source>/recipes)
//
// Every demo image gets a sidecar `<image>.json` with the scene's ground truth plus "serial" and
// "expected_verdict" ("pass" or "fail") and, for failing parts, the "defect" that makes them
// fail. The defects are far outside the example recipes' tolerances and the good parts' spread
// far inside, so the verdicts do not hinge on measurement noise.
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <random>
#include <string>

#include "algorithms/geometry/pose2d.hpp"
#include "tests/support/scene/parts.hpp"
#include "tests/support/scene/scene.hpp"

namespace fs = std::filesystem;
using facet::Pose2D;
using facet::radians;
using namespace facet::scene;

namespace {

constexpr double kBackground = 40.0;
constexpr double kPartGrey = 200.0;

SceneSpec liveSpec(std::uint64_t seed) {
  SceneSpec spec;
  spec.background = kBackground;
  spec.blurSigma = 0.8;
  spec.noiseSigma = 0.5;
  spec.seed = seed;
  spec.subrows = 64;
  return spec;
}

std::string numbered(const std::string& stem, int i, const std::string& ext) {
  char name[64];
  std::snprintf(name, sizeof name, "%s_%03d%s", stem.c_str(), i, ext.c_str());
  return name;
}

// `measured`: the value the recipe must find on a bad part, so that the golden-set gate fails a
// part that fails for another reason than its defect ({name, value}, held to 0.01 mm).
void annotate(Scene& scene, const std::string& serial, bool pass, const std::string& defect,
              const Pose2D& pose, const std::pair<std::string, double>& measured = {}) {
  auto& a = scene.annotations();
  a["serial"] = serial;
  a["expected_verdict"] = pass ? "pass" : "fail";
  if (!defect.empty()) a["defect"] = defect;
  if (!measured.first.empty())
    a["expected_values"] = {{measured.first, {{"value", measured.second}, {"tolerance", 0.01}}}};
  a["pose"] = {{"x", pose.x}, {"y", pose.y}, {"angle_deg", facet::degrees(pose.angle)}};
}

// Good parts vary in pose only; every fourth part is bad.
Pose2D randomPose(std::mt19937_64& rng, double shift, double angleDeg) {
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  return {320.0 + shift * u(rng), 240.0 + shift * u(rng), radians(angleDeg * u(rng)), 1.0};
}

// Recipe 1 (registration + circles + distance): big hole Ø1.0 mm, big-to-small 4.0 mm.
void bracketRegistration(const fs::path& root) {
  const PartDrawing part = bracketPart();
  Scene reference(liveSpec(11));
  placePart(reference, part, {320, 240, 0, 1}, kPartGrey, kBackground);
  reference.write(root / "models/bracket_reference.png");

  const fs::path folder = root / "demo/bracket_registration";
  fs::create_directories(folder);
  std::mt19937_64 rng(101);
  for (int i = 0; i < 12; ++i) {
    const Pose2D pose = randomPose(rng, 40.0, 20.0);
    PartDrawing drawn = part;
    std::string defect;
    std::pair<std::string, double> measured;
    if (i == 3) {
      drawn.primitives[1].radius = 12.0;
      defect = "big hole Ø1.2 mm (nominal 1.0)";
      measured = {"big_bore.diameter", 1.2};
    } else if (i == 7) {
      drawn.primitives[2].centre.x += 10.0;
      defect = "small hole 0.5 mm off";
      measured = {"small_bore.position", 0.5};
    } else if (i == 11) {
      drawn.primitives[1].radius = 8.5;
      defect = "big hole Ø0.85 mm (nominal 1.0)";
      measured = {"big_bore.diameter", 0.85};
    }
    Scene scene(liveSpec(1000 + i));
    placePart(scene, drawn, pose, kPartGrey, kBackground);
    annotate(scene, numbered("BR", i, ""), defect.empty(), defect, pose, measured);
    scene.write(folder / numbered("part", i, ".png"));
  }
}

std::vector<cv::Point2d> labelOutline() {
  return {{-14, -8}, {10, -8}, {16, 0}, {10, 8}, {-14, 8}, {-8, 0}};
}

// Recipe 2 (shape align + shape + circle + point_to_line + angle): a label beside the bracket.
void bracketShape(const fs::path& root) {
  const PartDrawing part = bracketPart();
  SceneSpec templateSpec = liveSpec(21);
  templateSpec.noiseSigma = 0.0;
  templateScene(part, templateSpec, kPartGrey).write(root / "models/bracket_template.png");

  SceneSpec labelSpec = templateSpec;
  labelSpec.size = {48, 32};
  Scene label(labelSpec);
  std::vector<cv::Point2d> outline = labelOutline();
  for (auto& p : outline) p += cv::Point2d(23.5, 15.5);
  label.addPolygon(outline, 150.0);
  label.write(root / "models/label_template.png");

  const fs::path folder = root / "demo/bracket_shape";
  fs::create_directories(folder);
  std::mt19937_64 rng(202);
  const cv::Point2d labelAt{35.0, 28.0};  // in the bracket's model coordinates
  for (int i = 0; i < 12; ++i) {
    const Pose2D pose = randomPose(rng, 40.0, 25.0);
    std::string defect;
    double labelAngle = 0.0;
    bool labelPresent = true;
    if (i == 3) labelPresent = false, defect = "label missing";
    if (i == 7) labelAngle = 15.0, defect = "label turned 15 deg";
    if (i == 11) labelAngle = -12.0, defect = "label turned -12 deg";
    Scene scene(liveSpec(2000 + i));
    placePart(scene, part, pose, kPartGrey, kBackground);
    if (labelPresent) {
      const Pose2D labelPose = pose.compose({labelAt.x, labelAt.y, radians(labelAngle), 1.0});
      std::vector<cv::Point2d> placed;
      for (const auto& p : labelOutline()) placed.push_back(labelPose.apply(p));
      scene.addPolygon(placed, 150.0);
    }
    annotate(scene, numbered("BS", i, ""), defect.empty(), defect, pose);
    scene.write(folder / numbered("part", i, ".png"));
  }
}

// Recipe 3 (fiducials + circle + distance): a plate with three dark marks and a bore.
void fiducialBoard(const fs::path& root) {
  const fs::path folder = root / "demo/fiducial_board";
  fs::create_directories(folder);
  const std::vector<cv::Point2d> marks{{-150, -125}, {150, -125}, {-150, 125}};
  std::mt19937_64 rng(303);
  for (int i = 0; i < 12; ++i) {
    Pose2D pose = randomPose(rng, 8.0, 2.0);
    double boreRadius = 20.0;
    std::string defect;
    if (i == 3) pose.angle = radians(12.0), defect = "board turned 12 deg";
    if (i == 7) boreRadius = 23.0, defect = "bore Ø2.3 mm (nominal 2.0)";
    if (i == 11) pose.angle = radians(-9.0), defect = "board turned -9 deg";
    Scene scene(liveSpec(3000 + i));
    std::vector<cv::Point2d> plate;
    for (const auto& c :
         std::vector<cv::Point2d>{{-190, -160}, {190, -160}, {190, 160}, {-190, 160}})
      plate.push_back(pose.apply(c));
    scene.addPolygon(plate, 180.0);
    for (const auto& m : marks) scene.addDisc(pose.apply(m), 8.0, 30.0);
    scene.addDisc(pose.apply({0, 0}), boreRadius, kBackground, "hole");
    annotate(scene, numbered("FB", i, ""), defect.empty(), defect, pose);
    scene.write(folder / numbered("board", i, ".png"));
  }
}

// An L-shaped corner seen by a 2D range sensor: x forward, y left, metres.
std::vector<cv::Point2d> cornerProfile() {
  std::vector<cv::Point2d> points;
  for (int k = 0; k <= 120; ++k) points.push_back({1.5, -0.6 + 0.01 * k});
  for (int k = 1; k <= 70; ++k) points.push_back({1.5 - 0.01 * k, 0.6});
  return points;
}

void writeScan(const fs::path& file, const std::vector<cv::Point2d>& points) {
  std::ofstream out(file);
  out << "x,y\n";
  char row[64];
  for (const auto& p : points) {
    std::snprintf(row, sizeof row, "%.5f,%.5f\n", p.x, p.y);
    out << row;
  }
}

// Recipe 4 (scan_align): the corner seen from a slightly different place each time.
void scanOffset(const fs::path& root) {
  fs::create_directories(root / "models");
  writeScan(root / "models/corner_reference.csv", cornerProfile());
  const fs::path folder = root / "demo/scan_offset";
  fs::create_directories(folder);
  std::mt19937_64 rng(404);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  std::normal_distribution<double> noise(0.0, 0.001);
  for (int i = 0; i < 10; ++i) {
    Pose2D offset{0.003 * u(rng), 0.003 * u(rng), radians(0.3 * u(rng)), 1.0};
    std::string defect;
    if (i == 3) offset.x = 0.025, defect = "fixture 25 mm off along x";
    if (i == 7) offset.angle = radians(3.0), defect = "fixture turned 3 deg";
    std::vector<cv::Point2d> points;
    for (const auto& p : cornerProfile()) {
      const cv::Point2d q = offset.apply(p);
      points.push_back({q.x + noise(rng), q.y + noise(rng)});
    }
    const fs::path file = folder / numbered("scan", i, ".csv");
    writeScan(file, points);
    nlohmann::json sidecar{{"serial", numbered("SC", i, "")},
                           {"expected_verdict", defect.empty() ? "pass" : "fail"},
                           {"offset",
                            {{"x_mm", offset.x * 1000},
                             {"y_mm", offset.y * 1000},
                             {"angle_deg", facet::degrees(offset.angle)}}}};
    if (!defect.empty()) sidecar["defect"] = defect;
    std::ofstream(file.string() + ".json") << sidecar.dump(2) << "\n";
  }
}

}  // namespace

int main(int argc, char** argv) {
  const fs::path root = argc > 1 ? fs::path(argv[1]) : fs::path(FACET_SOURCE_DIR) / "recipes";
  try {
    fs::create_directories(root / "models");
    bracketRegistration(root);
    bracketShape(root);
    fiducialBoard(root);
    scanOffset(root);
  } catch (const std::exception& e) {
    std::cerr << "record_demo: " << e.what() << "\n";
    return 1;
  }
  std::cout << "record_demo: wrote " << (root / "models").string() << " and "
            << (root / "demo").string() << "\n";
  return 0;
}
