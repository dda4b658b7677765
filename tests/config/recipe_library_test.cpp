// The recipe library as the daemon uses it: reload keeps the last good version of a broken
// recipe, ids are unique across the folder, changes on disk are noticed.
#include <thread>

#include <gtest/gtest.h>

#include "config/recipe_library.hpp"
#include "service/engine/steps/circle_step.hpp"
#include "tests/config/config_test_support.hpp"

namespace facet::config::test {
namespace {

std::string recipeText(int id, const std::string& name, double diameter = 1.0,
                       const std::string& reference = "models/ref.png") {
  return "schema_version: 1\nid: " + std::to_string(id) + "\nname: " + name +
         "\nsteps:\n  - id: part\n    kind: align\n    method: registration\n"
         "    reference: " +
         reference +
         "\n  - id: hole\n    kind: circle\n"
         "    relative_to: part\n    centre: [10, 10]\n    nominal_diameter: " +
         std::to_string(diameter) + "\n    search_width: 0.2\n";
}

class Library : public testing::Test {
 protected:
  void SetUp() override { scratch.writeImage("models/ref.png"); }

  RecipeLibrary make() {
    RecipeLoadOptions options;
    options.root = scratch.path();
    return RecipeLibrary(facetSteps(), options);
  }

  // Rewrites a file so that its modification time surely differs.
  void rewrite(const std::string& name, const std::string& text) {
    const auto file = scratch.path() / name;
    const auto before = std::filesystem::exists(file) ? std::filesystem::last_write_time(file)
                                                      : std::filesystem::file_time_type{};
    scratch.write(name, text);
    std::filesystem::last_write_time(file, before + std::chrono::seconds(2));
  }

  ScratchFolder scratch;
};

TEST_F(Library, LoadsEveryRecipeFileBelowTheRoot) {
  scratch.write("a.recipe.yaml", recipeText(1, "A"));
  scratch.write("line2/b.recipe.yaml", recipeText(2, "B", 1.0, "../models/ref.png"));
  scratch.write("station.yaml", "not: a recipe\n");  // ignored: not *.recipe.yaml
  auto library = make();
  const auto report = library.reload();
  EXPECT_TRUE(report.diagnostics.empty()) << report.diagnostics.text();
  EXPECT_EQ(report.loaded, (std::vector<int>{1, 2}));
  ASSERT_EQ(library.recipes().size(), 2u);
  ASSERT_NE(library.find(2), nullptr);
  EXPECT_EQ(library.find(2)->name, "B");
  EXPECT_EQ(library.find(3), nullptr);
  EXPECT_FALSE(library.changedOnDisk());
  // Nothing changed: nothing is read again.
  EXPECT_FALSE(library.reload().changed());
}

TEST_F(Library, BrokenFileKeepsTheLastGoodVersion) {
  scratch.write("a.recipe.yaml", recipeText(1, "A", 1.0));
  auto library = make();
  library.reload();
  const std::shared_ptr<const Recipe> inUse = library.find(1);
  ASSERT_NE(inUse, nullptr);

  rewrite("a.recipe.yaml", recipeText(1, "A", 1.0) + "    polarity: sideways\n");
  EXPECT_TRUE(library.changedOnDisk());
  const auto report = library.reload();
  ASSERT_EQ(report.rejected.size(), 1u);
  EXPECT_FALSE(report.changed());
  EXPECT_TRUE(hasDiagnostic(report.diagnostics, 15, 15, "unknown polarity 'sideways'"));
  EXPECT_EQ(library.find(1), inUse);  // the very same version stays active
  EXPECT_TRUE(library.problems().hasErrors());

  // Fixed: the new version replaces the old one; the old object stays valid for its holder.
  rewrite("a.recipe.yaml", recipeText(1, "A", 1.2));
  const auto fixed = library.reload();
  EXPECT_EQ(fixed.loaded, std::vector<int>{1});
  EXPECT_NE(library.find(1), inUse);
  EXPECT_DOUBLE_EQ(library.find(1)->steps[1].as<service::CircleParams>().nominalDiameter, 1.2);
  EXPECT_DOUBLE_EQ(inUse->steps[1].as<service::CircleParams>().nominalDiameter, 1.0);
  EXPECT_FALSE(library.problems().hasErrors());
}

TEST_F(Library, BrokenNewFileIsRejectedWithoutAffectingOthers) {
  scratch.write("a.recipe.yaml", recipeText(1, "A"));
  scratch.write("b.recipe.yaml", "schema_version: 1\nid: 2\nname: B\nsteps: [\n");
  auto library = make();
  const auto report = library.reload();
  EXPECT_EQ(report.loaded, std::vector<int>{1});
  ASSERT_EQ(report.rejected.size(), 1u);
  EXPECT_EQ(report.rejected[0].filename(), "b.recipe.yaml");
  EXPECT_EQ(library.find(2), nullptr);
}

TEST_F(Library, DuplicateIdsAcrossTheFolderAreRefused) {
  scratch.write("a.recipe.yaml", recipeText(1, "A"));
  auto library = make();
  library.reload();
  scratch.write("b.recipe.yaml", recipeText(1, "B"));
  const auto report = library.reload();
  ASSERT_EQ(report.rejected.size(), 1u);
  EXPECT_TRUE(hasDiagnostic(report.diagnostics, 2, 5, "recipe id 1 is already used by"));
  EXPECT_EQ(library.find(1)->name, "A");  // the recipe in use keeps its id

  // Once the first file is gone, the second one gets the id.
  std::filesystem::remove(scratch.path() / "a.recipe.yaml");
  EXPECT_TRUE(library.changedOnDisk());
  const auto after = library.reload();
  EXPECT_EQ(after.removed, std::vector<int>{1});
  EXPECT_EQ(after.loaded, std::vector<int>{1});
  EXPECT_EQ(library.find(1)->name, "B");
}

TEST_F(Library, AFileReplacedWithTheSameSizeAndModificationTimeIsReloaded) {
  // What `cp -p` or `rsync -t` of an edited recipe does: 1.1 -> 1.3 keeps the size, and the
  // modification time is set back to the old file's.
  scratch.write("a.recipe.yaml", recipeText(1, "A", 1.1));
  const auto file = scratch.path() / "a.recipe.yaml";
  const auto size = std::filesystem::file_size(file);
  const auto modified = std::filesystem::last_write_time(file);
  auto library = make();
  library.reload();
  ASSERT_NE(library.find(1), nullptr);
  const double before = library.find(1)->steps.at(1).as<service::CircleParams>().nominalDiameter;

  std::this_thread::sleep_for(std::chrono::milliseconds(20));  // a later status-change time
  scratch.write("a.recipe.yaml", recipeText(1, "A", 1.3));
  std::filesystem::last_write_time(file, modified);
  ASSERT_EQ(std::filesystem::file_size(file), size);
  ASSERT_EQ(std::filesystem::last_write_time(file), modified);

  EXPECT_TRUE(library.changedOnDisk());
  const auto report = library.reload();
  EXPECT_EQ(report.loaded, (std::vector<int>{1}));
  EXPECT_DOUBLE_EQ(before, 1.1);
  EXPECT_DOUBLE_EQ(library.find(1)->steps.at(1).as<service::CircleParams>().nominalDiameter, 1.3);
}

TEST_F(Library, AChangedImageReloadsTheRecipe) {
  scratch.write("a.recipe.yaml", recipeText(1, "A"));
  auto library = make();
  library.reload();
  const auto before = library.find(1);
  const auto image = scratch.path() / "models/ref.png";
  const auto stamp = std::filesystem::last_write_time(image);
  scratch.writeImage("models/ref.png", 80, 60);
  std::filesystem::last_write_time(image, stamp + std::chrono::seconds(2));
  EXPECT_TRUE(library.changedOnDisk());
  EXPECT_EQ(library.reload().loaded, std::vector<int>{1});
  EXPECT_NE(library.find(1), before);
}

TEST_F(Library, ReadersDuringReloadAlwaysSeeACompleteRecipe) {
  scratch.write("a.recipe.yaml", recipeText(1, "A", 1.0));
  auto library = make();
  library.reload();
  std::atomic<bool> stop{false};
  std::atomic<int> reads{0};
  std::thread reader([&] {
    while (!stop) {
      const auto r = library.find(1);
      ASSERT_NE(r, nullptr);
      ASSERT_EQ(r->steps.size(), 2u);
      ++reads;
    }
  });
  for (int i = 0; i < 20; ++i) {
    rewrite("a.recipe.yaml", recipeText(1, "A", 1.0 + 0.01 * i) + (i % 2 ? "  - broken\n" : ""));
    library.reload();
  }
  stop = true;
  reader.join();
  EXPECT_GT(reads.load(), 0);
  EXPECT_NE(library.find(1), nullptr);
}

}  // namespace
}  // namespace facet::config::test
