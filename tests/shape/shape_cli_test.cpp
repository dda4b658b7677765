// `facet model create` and `facet match`: the real binary on generated images.
#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <string>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>
#include <opencv2/imgcodecs.hpp>

#include "tests/shape/bracket_scenes.hpp"

namespace facet {
namespace {

namespace fs = std::filesystem;

struct CliRun {
  int exitCode = -1;
  std::string out;
};

// Runs a shell command, capturing stdout (stderr goes to `errFile`).
CliRun run(const std::string& command, const fs::path& errFile) {
  CliRun r;
  FILE* pipe = popen((command + " 2>" + errFile.string()).c_str(), "r");
  if (!pipe) return r;
  std::array<char, 4096> buffer{};
  std::size_t n = 0;
  while ((n = fread(buffer.data(), 1, buffer.size(), pipe)) > 0) r.out.append(buffer.data(), n);
  const int status = pclose(pipe);
  r.exitCode = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  return r;
}

std::string readText(const fs::path& p) {
  std::ifstream in(p);
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

// A temporary directory with the bracket's template, a scene of it at `truth` and the model
// trained from the template with `createOptions`; `match` is `facet match` of that model on the
// scene. `trained` is false (stderr in `err`) when training failed.
struct TrainedScene {
  fs::path dir, err;
  std::string match;
  bool trained = false;
};

TrainedScene trainedScene(const std::string& name, const Pose2D& truth, std::uint64_t seed,
                          const std::string& createOptions = {}) {
  TrainedScene t;
  t.dir = fs::temp_directory_path() / name;
  fs::create_directories(t.dir);
  t.err = t.dir / "stderr.txt";
  const std::string cli = FACET_CLI, model = (t.dir / "part.model").string();
  if (!cv::imwrite((t.dir / "template.png").string(), testing::bracketTemplate()) ||
      !cv::imwrite((t.dir / "scene.png").string(),
                   testing::bracketScene({480, 360}, {truth}, seed)))
    return t;
  t.trained = run(cli + " model create --image " + (t.dir / "template.png").string() +
                      createOptions + " --out " + model,
                  t.err)
                  .exitCode == 0;
  t.match = cli + " match --model " + model + " --image " + (t.dir / "scene.png").string();
  return t;
}

TEST(ShapeCli, CreateThenMatchPrintsThePoseAsJson) {
  const fs::path dir = fs::temp_directory_path() / "facet_shape_cli_test";
  fs::create_directories(dir);
  const std::string cli = FACET_CLI;
  const fs::path err = dir / "stderr.txt";

  // Template inside a larger image, trained through --roi.
  const cv::Mat templ = testing::bracketTemplate();
  cv::Mat big(200, 260, CV_8U, cv::Scalar(testing::kBackground));
  templ.copyTo(big(cv::Rect(40, 30, templ.cols, templ.rows)));
  ASSERT_TRUE(cv::imwrite((dir / "template.png").string(), big));
  const Pose2D truth{250.4, 170.8, radians(-72.5), 1.0};
  ASSERT_TRUE(
      cv::imwrite((dir / "scene.png").string(), testing::bracketScene({480, 360}, {truth}, 3)));

  const CliRun create =
      run(cli + " model create --image " + (dir / "template.png").string() +
              " --roi 40,30,160,130 --out " + (dir / "part.model").string() + " --json",
          err);
  ASSERT_EQ(create.exitCode, 0) << readText(err);
  const auto created = nlohmann::json::parse(create.out);
  EXPECT_GE(created.at("levels").get<int>(), 3);
  // The automatic pyramid's test: the depth its edges allow finds every copy, and is kept.
  ASSERT_EQ(created.at("pyramid_trials").size(), 1u);
  EXPECT_EQ(created.at("pyramid_trials")[0].at("levels"), created.at("levels"));
  EXPECT_EQ(created.at("pyramid_trials")[0].at("copies_lost").get<int>(), 0);
  EXPECT_DOUBLE_EQ(created.at("reference")[0].get<double>(), 79.5);
  // The automatic edge estimator and the training test behind it: a part of blurred steps.
  EXPECT_EQ(created.at("edge_estimator"), "profile");
  EXPECT_EQ(created.at("edge_estimator_chosen"), "automatic");
  EXPECT_LT(created.at("edge_estimator_trials").at("profile").get<double>(),
            created.at("edge_estimator_trials").at("zero-crossing").get<double>());
  // The automatic minimum contour length, and one given by hand.
  EXPECT_EQ(created.at("min_component").get<int>(), 10);
  EXPECT_EQ(created.at("min_component_chosen"), "automatic");
  const CliRun keepAll = run(cli + " model create --image " + (dir / "template.png").string() +
                                 " --roi 40,30,160,130 --min-component 0 --out " +
                                 (dir / "all.model").string() + " --json",
                             err);
  ASSERT_EQ(keepAll.exitCode, 0) << readText(err);
  EXPECT_EQ(nlohmann::json::parse(keepAll.out).at("min_component").get<int>(), 0);
  EXPECT_EQ(nlohmann::json::parse(keepAll.out).at("min_component_chosen"), "--min-component");
  const CliRun negative = run(cli + " model create --image " + (dir / "template.png").string() +
                                  " --min-component -2 --out " + (dir / "x.model").string(),
                              err);
  EXPECT_EQ(negative.exitCode, 1);
  EXPECT_NE(readText(err).find("--min-component"), std::string::npos) << readText(err);

  const CliRun match = run(cli + " match --model " + (dir / "part.model").string() + " --image " +
                               (dir / "scene.png").string() +
                               " --min-score 0.7 --num-matches 1 --subpixel least_squares --json",
                           err);
  ASSERT_EQ(match.exitCode, 0) << readText(err);
  const auto result = nlohmann::json::parse(match.out);
  ASSERT_EQ(result.at("matches").size(), 1u) << match.out;
  const auto& m = result["matches"][0];
  EXPECT_NEAR(m.at("x").get<double>(), truth.x, 0.05);
  EXPECT_NEAR(m.at("y").get<double>(), truth.y, 0.05);
  EXPECT_NEAR(m.at("angle").get<double>(), -72.5, 0.03);  // degrees
  EXPECT_NEAR(m.at("scale").get<double>(), 1.0, 1e-3);
  EXPECT_GT(m.at("score").get<double>(), 0.9);
  EXPECT_GE(result.at("time_ms").get<double>(), 0.0);

  // Restricting the angle range away from the part finds nothing (and is not an error).
  const CliRun none = run(cli + " match --model " + (dir / "part.model").string() + " --image " +
                              (dir / "scene.png").string() + " --angle-range 0,90 --json",
                          err);
  ASSERT_EQ(none.exitCode, 0) << readText(err);
  EXPECT_TRUE(nlohmann::json::parse(none.out).at("matches").empty());

  // Bad input: exit 1 and an error naming the file.
  std::ofstream(dir / "bad.model") << "not a model";
  const CliRun bad = run(cli + " match --model " + (dir / "bad.model").string() + " --image " +
                             (dir / "scene.png").string() + " --json",
                         err);
  EXPECT_EQ(bad.exitCode, 1);
  EXPECT_NE(readText(err).find("bad.model"), std::string::npos) << readText(err);

  const CliRun flat = run(cli + " model create --image " + (dir / "template.png").string() +
                              " --roi 0,0,30,25 --out " + (dir / "flat.model").string(),
                          err);
  EXPECT_EQ(flat.exitCode, 1);
  EXPECT_NE(readText(err).find("too few edges"), std::string::npos) << readText(err);

  const CliRun badRoi = run(cli + " model create --image " + (dir / "template.png").string() +
                                " --roi 1,2,x --out " + (dir / "x.model").string(),
                            err);
  EXPECT_EQ(badRoi.exitCode, 1);
  EXPECT_NE(readText(err).find("--roi"), std::string::npos) << readText(err);
  fs::remove_all(dir);
}

// A model trained for -10..10 degrees cannot find a part turned 30 degrees, whatever range the
// search asks for: the cut is said on stderr and in the JSON, not left to a silent "0 matches".
// Search options out of range are argument errors under the user's option names.
TEST(ShapeCli, MatchSaysWhenTheModelCutsTheRequestedRange) {
  const TrainedScene scene = trainedScene(
      "facet_shape_cli_range_test", {240.3, 180.6, radians(30.0), 1.0}, 4, " --angle-range -10,10");
  ASSERT_TRUE(scene.trained) << readText(scene.err);
  const std::string& match = scene.match;
  const fs::path& err = scene.err;

  const CliRun wide = run(match + " --angle-range -180,180 --json", err);
  ASSERT_EQ(wide.exitCode, 0) << readText(err);
  const auto j = nlohmann::json::parse(wide.out);
  ASSERT_EQ(j.at("warnings").size(), 1u) << wide.out;
  const std::string warning = j["warnings"][0].get<std::string>();
  EXPECT_NE(warning.find("--angle-range"), std::string::npos) << warning;
  EXPECT_NE(warning.find("-10,10"), std::string::npos) << warning;

  const CliRun text = run(match + " --angle-range -180,180 --scale-range 0.9,1.1", err);
  ASSERT_EQ(text.exitCode, 0) << readText(err);
  EXPECT_NE(readText(err).find("warning: --angle-range -180,180 is cut"), std::string::npos)
      << readText(err);
  EXPECT_NE(readText(err).find("warning: --scale-range 0.9,1.1 is cut"), std::string::npos)
      << readText(err);

  // Inside the trained range: nothing to say.
  const CliRun inside = run(match + " --angle-range -5,5 --json", err);
  ASSERT_EQ(inside.exitCode, 0) << readText(err);
  EXPECT_TRUE(nlohmann::json::parse(inside.out).at("warnings").empty()) << inside.out;

  for (const std::string option :
       {"--min-score 1.5", "--min-score 0", "--max-overlap 2", "--greediness -1",
        "--num-matches -3", "--scale-tolerance 0.2", "--scale-tolerance -0.01",
        "--max-deformation 9", "--max-deformation -1",
        "--max-deformation 1 --polarity ignore_global"}) {
    const CliRun bad = run(match + " " + option, err);
    EXPECT_EQ(bad.exitCode, 1) << option;
    const std::string message = readText(err);
    EXPECT_NE(message.find(option.substr(0, option.find(' '))), std::string::npos) << message;
    EXPECT_EQ(message.find("findShapeModel"), std::string::npos) << message;
    EXPECT_EQ(message.find("scene.png"), std::string::npos) << "not the image's fault: " << message;
  }
  fs::remove_all(scene.dir);
}

// A part 1.2% larger than its one-scale model: the subpixel fit finds its scale within the
// default tolerance, and holds the model's with --scale-tolerance 0.
TEST(ShapeCli, ScaleToleranceDecidesWhetherTheFitFollowsAPartsScale) {
  const Pose2D truth{240.3, 180.6, radians(31.0), 1.012};
  const TrainedScene scene = trainedScene("facet_shape_cli_scale_test", truth, 5);
  ASSERT_TRUE(scene.trained) << readText(scene.err);
  const std::string match = scene.match + " --json";
  const fs::path& err = scene.err;
  for (const std::string tolerance : {"", " --scale-tolerance 0"}) {
    const CliRun r = run(match + tolerance, err);
    ASSERT_EQ(r.exitCode, 0) << readText(err);
    const auto j = nlohmann::json::parse(r.out);
    ASSERT_EQ(j.at("matches").size(), 1u) << r.out;
    const double scale = j["matches"][0].at("scale").get<double>();
    if (tolerance.empty())
      EXPECT_NEAR(scale, truth.scale, 1e-3) << r.out;
    else
      EXPECT_EQ(scale, 1.0) << r.out;
  }
  fs::remove_all(scene.dir);
}

// --max-deformation reaches the search: on an exact part the pose is the rigid one and the score
// can only rise (every model point meets its edge within the tolerance).
TEST(ShapeCli, MaxDeformationKeepsTheRigidPoseOfAnExactPart) {
  const Pose2D truth{240.3, 180.6, radians(31.0), 1.0};
  const TrainedScene scene = trainedScene("facet_shape_cli_deformation_test", truth, 6);
  ASSERT_TRUE(scene.trained) << readText(scene.err);
  const CliRun rigid = run(scene.match + " --json", scene.err);
  const CliRun tolerant = run(scene.match + " --max-deformation 2 --json", scene.err);
  ASSERT_EQ(rigid.exitCode, 0) << readText(scene.err);
  ASSERT_EQ(tolerant.exitCode, 0) << readText(scene.err);
  const auto a = nlohmann::json::parse(rigid.out).at("matches");
  const auto b = nlohmann::json::parse(tolerant.out).at("matches");
  ASSERT_EQ(a.size(), 1u) << rigid.out;
  ASSERT_EQ(b.size(), 1u) << tolerant.out;
  EXPECT_NEAR(b[0].at("x").get<double>(), a[0].at("x").get<double>(), 1e-6);
  EXPECT_NEAR(b[0].at("y").get<double>(), a[0].at("y").get<double>(), 1e-6);
  EXPECT_GE(b[0].at("score").get<double>(), a[0].at("score").get<double>());
  fs::remove_all(scene.dir);
}

// A depth the automatic pyramid refused because the part's pattern repeats within its top level's
// reach is printed with the period (template pixels) instead of copies lost.
TEST(ShapeCli, CreatePrintsThePeriodThatRefusedADepth) {
  const fs::path dir = fs::temp_directory_path() / "facet_shape_cli_period_test";
  fs::create_directories(dir);
  const fs::path err = dir / "stderr.txt";
  cv::Mat board(240, 240, CV_8U);
  for (int y = 0; y < board.rows; ++y)
    for (int x = 0; x < board.cols; ++x)
      board.at<std::uint8_t>(y, x) = ((x / 8 + y / 8) % 2) ? 200 : 50;
  ASSERT_TRUE(cv::imwrite((dir / "board.png").string(), board));
  const CliRun create =
      run(std::string(FACET_CLI) + " model create --image " + (dir / "board.png").string() +
              " --roi 53,59,70,60 --out " + (dir / "board.model").string() + " --json",
          err);
  ASSERT_EQ(create.exitCode, 0) << readText(err);
  const auto trials = nlohmann::json::parse(create.out).at("pyramid_trials");
  ASSERT_GE(trials.size(), 2u) << create.out;
  EXPECT_GT(trials[0].at("levels").get<int>(), nlohmann::json::parse(create.out).at("levels"));
  ASSERT_EQ(trials[0].at("period").size(), 2u);
  const double length =
      std::hypot(trials[0].at("period")[0].get<double>(), trials[0].at("period")[1].get<double>());
  EXPECT_GT(length, 10.0);  // a square's diagonal, 11.3 px, or longer
  EXPECT_GT(trials[0].at("period_score").get<double>(), 0.6);
  EXPECT_FALSE(trials[0].contains("copies_lost"));
  EXPECT_TRUE(trials.back().contains("copies_lost"));
  // A board patch whose period the depth keeps: none is tracked beside it.
  EXPECT_TRUE(nlohmann::json::parse(create.out).at("tracked_periods").empty()) << create.out;
  fs::remove_all(dir);
}

// A chessboard photographed at a slant keeps its depth; the periods its top level cannot tell
// apart are tracked by the search, each with its opposite, and printed.
TEST(ShapeCli, CreatePrintsTheTrackedPeriods) {
  const fs::path dir = fs::temp_directory_path() / "facet_shape_cli_tracked_test";
  fs::create_directories(dir);
  const fs::path err = dir / "stderr.txt";
  const CliRun create = run(std::string(FACET_CLI) + " model create --image " +
                                FACET_TEST_DATA_DIR + "/photos/slanted_board_template.png --out " +
                                (dir / "board.model").string() + " --json",
                            err);
  ASSERT_EQ(create.exitCode, 0) << readText(err);
  const auto periods = nlohmann::json::parse(create.out).at("tracked_periods");
  ASSERT_FALSE(periods.empty()) << create.out;
  for (const auto& p : periods) {
    const double x = p.at("shift")[0].get<double>(), y = p.at("shift")[1].get<double>();
    EXPECT_GT(std::hypot(x, y), 8.0);  // a pixel of the top level (1/8) or more
    EXPECT_GE(p.at("score").get<double>(), 0.49);
    const bool opposite = std::any_of(periods.begin(), periods.end(), [&](const nlohmann::json& q) {
      return std::hypot(q.at("shift")[0].get<double>() + x, q.at("shift")[1].get<double>() + y) <=
             1.5;
    });
    EXPECT_TRUE(opposite) << p;
  }
  fs::remove_all(dir);
}

}  // namespace
}  // namespace facet
