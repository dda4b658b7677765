// libFuzzer target: the recipe parser and validator (config/recipe_loader.hpp). Each input is a
// recipe file in a recipes folder that also holds a small image (part.png, models/part.png) and
// a scan (models/scan.csv), so that inputs naming them reach the file checks. Expected outcome
// for bad input: diagnostics, each naming the recipe file. A recipe is returned exactly when
// there is no error.

#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <fstream>

#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "config/recipe_loader.hpp"
#include "service/engine/builtin_steps.hpp"
#include "tests/fuzz/fuzz_input_file.hpp"

namespace {

const facet::fuzz::FuzzInputFolder& recipesFolder() {
  static const facet::fuzz::FuzzInputFolder folder;
  static const bool filled = [] {
    const auto& root = folder.path();
    std::filesystem::create_directories(root / "models");
    cv::Mat image(48, 64, CV_8UC1, cv::Scalar(40));
    cv::circle(image, {32, 24}, 10, cv::Scalar(200), -1);
    cv::imwrite((root / "part.png").string(), image);
    cv::imwrite((root / "models" / "part.png").string(), image);
    std::ofstream scan(root / "models" / "scan.csv");
    scan << "x,y\n1.0,0.0\n1.0,0.1\n1.0,0.2\n0.9,0.2\n0.8,0.2\n";
    return true;
  }();
  (void)filled;
  return folder;
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const auto& folder = recipesFolder();
  const auto file = folder.write("fuzz.recipe.yaml", data, size);
  facet::config::RecipeLoadOptions options;
  options.root = folder.path();
  options.requireTrainedModels = (size % 2) == 0;  // both ways the daemon and `train` read
  static const auto kinds = facet::service::builtinSteps();
  const auto result = facet::config::loadRecipe(file, kinds, options);
  if (result.recipe.has_value() == result.diagnostics.hasErrors()) std::abort();
  return 0;
}
