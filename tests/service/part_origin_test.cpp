#include <gtest/gtest.h>

#include "service/daemon/part_origin.hpp"

namespace facet::service {
namespace {

TEST(PartOrigin, RecipeFrameAndSidecarReachThePart) {
  config::Recipe recipe;
  recipe.id = 7;
  recipe.name = "bracket";
  recipe.contentHash = "0123456789abcdef";
  Frame frame;
  frame.id = 41;
  frame.source = "/line/part_041.png";
  frame.metadata = {{"serial", "SN-41"}, {"expected_verdict", "fail"}, {"operator", "x"}};

  PartResult part;
  recordPartOrigin(part, &recipe, frame);
  EXPECT_EQ(part.recipeId, 7);
  EXPECT_EQ(part.recipeName, "bracket");
  EXPECT_EQ(part.recipeVersion, "0123456789abcdef");
  EXPECT_EQ(part.frameId, 41u);
  EXPECT_EQ(part.source, "/line/part_041.png");
  EXPECT_EQ(part.serial, "SN-41");
  EXPECT_EQ(part.expectedVerdict, "fail");
}

TEST(PartOrigin, WithoutRecipeOrSidecarOnlyTheFrameIsRecorded) {
  Frame frame;
  frame.id = 3;
  frame.source = "camera:FACET-1";
  PartResult part;
  recordPartOrigin(part, nullptr, frame);
  EXPECT_EQ(part.recipeId, 0);
  EXPECT_TRUE(part.recipeName.empty() && part.recipeVersion.empty());
  EXPECT_EQ(part.frameId, 3u);
  EXPECT_EQ(part.source, "camera:FACET-1");
  EXPECT_TRUE(part.serial.empty() && part.expectedVerdict.empty());
}

}  // namespace
}  // namespace facet::service
