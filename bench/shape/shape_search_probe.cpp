// shape_search_probe: two checks for work on the search's speed.
//   shape_search_probe poses [DATA_DIR]   every match (min score 0.3, all matches) of a set of
//                                         bracket scenes and the photographs, 17 digits: a
//                                         change that must not move results leaves it identical
//   shape_search_probe warm N             N 640x480 scenes (those of bench_shape_real's speed
//                                         row) searched twice; under valgrind --tool=callgrind
//                                         --collect-atstart=no only the second round is counted:
//                                         warm searches, with the blur tables that the first
//                                         round built (as on a line after its first images)
//   shape_search_probe cold N             the same, counting the first round: a line's first N
//                                         images, which build the blur tables as they go

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <numbers>
#include <sstream>
#include <string>
#include <vector>

#include <valgrind/callgrind.h>
#include <opencv2/imgcodecs.hpp>

#include "algorithms/shape/find_shape_model.hpp"
#include "algorithms/shape/shape_model.hpp"
#include "tests/shape/bracket_scenes.hpp"

namespace {

using namespace facet;

void print(const char* name, const std::vector<ShapeMatch>& matches) {
  std::printf("%s: %zu\n", name, matches.size());
  for (const auto& m : matches)
    std::printf("  %.17g %.17g %.17g %.17g %.17g %.17g\n", m.x, m.y, m.angle, m.scale, m.score,
                m.residual);
}

Pose2D speedPose(cv::Size size, int i, bool next) {
  const double u = (i * 0.618034) - std::floor(i * 0.618034);
  const Pose2D truth{size.width * (0.3 + 0.4 * u), size.height * (0.35 + 0.3 * (1 - u)),
                     (2 * u - 1) * std::numbers::pi, 1.0};
  if (!next) return truth;
  return {size.width - truth.x, size.height - truth.y, wrapAngle(truth.angle + 2.0), 1.0};
}

int poses(const std::filesystem::path& data) {
  FindParams all;
  all.minScore = 0.3;
  all.numMatches = 0;
  const ShapeModel model = createShapeModel(testing::bracketTemplate());
  char name[128];
  for (const cv::Size size : {cv::Size(640, 480), cv::Size(1280, 1024)})
    for (int i = 0; i < 8; ++i)
      for (const bool next : {false, true}) {
        const cv::Mat image =
            testing::bracketScene(size, {speedPose(size, i, next)}, (next ? 900 : 500) + i);
        std::snprintf(name, sizeof name, "bracket %dx%d %d %d", size.width, size.height, i, next);
        print(name, findShapeModel(image, model, all));
      }
  // Several parts, touching and overlapping; inverted contrast; 16 bits; a scale range.
  const std::vector<Pose2D> many{{150, 140, 0.3, 1.0},
                                 {330, 150, -2.0, 1.0},
                                 {420, 330, 1.2, 1.0},
                                 {480, 300, 2.9, 1.0},
                                 {200, 350, -0.7, 1.0}};
  const cv::Mat crowd = testing::bracketScene({640, 480}, many, 33);
  print("crowd", findShapeModel(crowd, model, all));
  FindParams global = all, local = all;
  global.polarity = Polarity::IgnoreGlobal;
  local.polarity = Polarity::IgnoreLocal;
  const cv::Mat inverted =
      testing::bracketScene({640, 480}, many, 34, testing::kBackground, testing::kPartGrey);
  print("inverted global", findShapeModel(inverted, model, global));
  print("crowd local", findShapeModel(crowd, model, local));
  const cv::Mat deep =
      testing::bracketScene({640, 480}, many, 35, testing::kPartGrey, testing::kBackground, CV_16U);
  print("crowd 16 bit", findShapeModel(deep, model, all));
  ShapeModelParams scaled;
  scaled.scaleMin = 0.9;
  scaled.scaleMax = 1.1;
  const ShapeModel scaledModel = createShapeModel(testing::bracketTemplate(), scaled);
  const cv::Mat sizes = testing::bracketScene(
      {640, 480}, {{170, 150, 0.4, 0.93}, {450, 160, -1.9, 1.07}, {320, 350, 2.5, 1.0}}, 36);
  print("scale range", findShapeModel(sizes, scaledModel, all));
  FindParams fixed = all;
  fixed.refineScaleTolerance = 0.0;
  print("scale range, fixed model", findShapeModel(sizes, model, fixed));

  std::ifstream in(data / "cases.txt");
  std::string line;
  while (std::getline(in, line)) {
    if (line.empty() || line[0] == '#') continue;
    std::istringstream s(line);
    std::string caseName, templ, scene;
    s >> caseName >> templ >> scene;
    const cv::Mat t = cv::imread((data / templ).string(), cv::IMREAD_GRAYSCALE);
    const cv::Mat image = cv::imread((data / scene).string(), cv::IMREAD_GRAYSCALE);
    if (t.empty() || image.empty()) return 1;
    print(caseName.c_str(), findShapeModel(image, createShapeModel(t), all));
  }
  return 0;
}

int rounds(int n, bool countFirst) {
  const ShapeModel model = createShapeModel(testing::bracketTemplate());
  const cv::Size size(640, 480);
  std::vector<cv::Mat> images;
  for (int i = 0; i < n; ++i)
    images.push_back(testing::bracketScene(size, {speedPose(size, i, true)}, 900 + i));
  int found = 0;
  for (const bool counted : {countFirst, !countFirst}) {
    if (counted) CALLGRIND_TOGGLE_COLLECT;
    for (const cv::Mat& image : images) found += !findShapeModel(image, model).empty();
    if (counted) CALLGRIND_TOGGLE_COLLECT;
  }
  std::printf("%d of %d found\n", found, 2 * n);
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  if (argc >= 2 && !std::strcmp(argv[1], "poses"))
    return poses(argc >= 3 ? argv[2]
                           : std::filesystem::path(FACET_SOURCE_DIR) / "tests/data/photos");
  if (argc >= 3 && !std::strcmp(argv[1], "warm")) return rounds(std::atoi(argv[2]), false);
  if (argc >= 3 && !std::strcmp(argv[1], "cold")) return rounds(std::atoi(argv[2]), true);
  std::fprintf(stderr, "usage: shape_search_probe poses [DATA_DIR] | warm N | cold N\n");
  return 2;
}
