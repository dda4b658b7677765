#include <gtest/gtest.h>

#include "config/closest_name.hpp"
#include "config/confined_path.hpp"

namespace facet::config {
namespace {

TEST(ClosestName, EditDistanceCountsSwapsAsOneEdit) {
  EXPECT_EQ(editDistance("min_score", "min_score"), 0u);
  EXPECT_EQ(editDistance("min_scor", "min_score"), 1u);
  EXPECT_EQ(editDistance("mni_score", "min_score"), 1u);  // swapped neighbours
  EXPECT_EQ(editDistance("", "abc"), 3u);
  EXPECT_EQ(editDistance("kitten", "sitting"), 3u);
}

TEST(ClosestName, SuggestsOnlyPlausibleTypos) {
  const std::vector<std::string> keys{"nominal", "tol_minus", "tol_plus", "unit", "plc"};
  EXPECT_EQ(closestName("tol_mnius", keys), "tol_minus");
  EXPECT_EQ(closestName("TOL_PLUS", keys), "tol_plus");
  EXPECT_EQ(closestName("nominl", keys), "nominal");
  EXPECT_FALSE(closestName("tolerance", keys).has_value());
  EXPECT_FALSE(closestName("colour", keys).has_value());
}

TEST(ConfinedPath, ResolvesInsideAndRefusesEscapes) {
  const std::filesystem::path root = std::filesystem::temp_directory_path() / "facet_confined";
  std::filesystem::create_directories(root / "sub");
  const auto inside = confinedPath("../models/a.png", root / "sub", root);
  ASSERT_TRUE(std::holds_alternative<std::filesystem::path>(inside));
  EXPECT_EQ(std::get<std::filesystem::path>(inside),
            (std::filesystem::weakly_canonical(root) / "models/a.png"));
  EXPECT_TRUE(std::holds_alternative<std::string>(confinedPath("../../x.png", root / "sub", root)));
  EXPECT_TRUE(std::holds_alternative<std::string>(confinedPath("/etc/passwd", root, root)));
  // A sibling folder whose name starts like the root is outside it.
  EXPECT_TRUE(std::holds_alternative<std::string>(
      confinedPath("../facet_confined_other/x.png", root, root)));
  std::filesystem::remove_all(root);
}

}  // namespace
}  // namespace facet::config
