// Hand edits under time pressure: whatever a typo does to an example recipe, loading it never
// throws or crashes, and every problem it reports points into the file.
#include <fstream>
#include <random>
#include <sstream>

#include <gtest/gtest.h>

#include "config/recipe_loader.hpp"
#include "config/station_config.hpp"
#include "tests/config/config_test_support.hpp"

namespace facet::config::test {
namespace {

const std::filesystem::path kRecipes = std::filesystem::path(FACET_SOURCE_DIR) / "recipes";

std::vector<std::string> linesOf(const std::filesystem::path& file) {
  std::ifstream in(file);
  std::vector<std::string> lines;
  for (std::string line; std::getline(in, line);) lines.push_back(line);
  return lines;
}

// One random edit: drop, duplicate or swap lines, or replace the value after a colon.
std::string mutate(std::vector<std::string> lines, std::mt19937& rng) {
  static const std::vector<std::string> values{"",      "[",         "{a: 1}", "-1", "x",
                                               "1e999", "[1, 2, 3]", "\"3\"",  "~",  "part"};
  std::uniform_int_distribution<std::size_t> pick(0, lines.size() - 1);
  const std::size_t i = pick(rng), j = pick(rng);
  switch (rng() % 4) {
    case 0:
      lines.erase(lines.begin() + static_cast<long>(i));
      break;
    case 1:
      lines.insert(lines.begin() + static_cast<long>(i), lines[j]);
      break;
    case 2:
      std::swap(lines[i], lines[j]);
      break;
    default:
      if (const auto colon = lines[i].find(": "); colon != std::string::npos)
        lines[i] = lines[i].substr(0, colon + 2) + values[rng() % values.size()];
      break;
  }
  std::ostringstream out;
  for (const auto& l : lines) out << l << "\n";
  return out.str();
}

TEST(RecipeRobustness, MutatedExamplesNeverThrowAndPointIntoTheFile) {
  ScratchFolder scratch;
  std::filesystem::copy(kRecipes / "models", scratch.path() / "models");
  std::mt19937 rng(7);
  int rejected = 0, runs = 0;
  for (const std::string name :
       {"bracket_registration", "bracket_shape", "fiducial_board", "scan_offset"}) {
    const auto lines = linesOf(kRecipes / (name + ".recipe.yaml"));
    for (int k = 0; k < 60; ++k, ++runs) {
      const std::string text = mutate(lines, rng);
      const auto file = scratch.write("m.recipe.yaml", text);
      RecipeLoadResult r;
      ASSERT_NO_THROW(r = loadRecipe(file, facetSteps(), {})) << text;
      EXPECT_EQ(r.recipe.has_value(), !r.diagnostics.hasErrors());
      if (!r.recipe) ++rejected;
      for (const auto& d : r.diagnostics.items()) {
        if (d.where.file != file) continue;  // e.g. a scan file's own line
        EXPECT_GT(d.where.line, 0) << format(d) << "\n" << text;
        EXPECT_GT(d.where.column, 0) << format(d) << "\n" << text;
      }
    }
  }
  // Most random edits break something; the test would be vacuous otherwise.
  EXPECT_GT(rejected, runs / 3);
}

}  // namespace
}  // namespace facet::config::test
