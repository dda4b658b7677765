#include "algorithms/calibration/board_spec.hpp"

#include <gtest/gtest.h>

namespace facet {
namespace {

TEST(BoardSpec, ParsesChessboardAndCircles) {
  std::string why;
  const auto c = parseBoardSpec("chessboard:11x8:10", why);
  ASSERT_TRUE(c) << why;
  EXPECT_EQ(c->kind, BoardSpec::Kind::Chessboard);
  EXPECT_EQ(c->cols, 11);
  EXPECT_EQ(c->rows, 8);
  EXPECT_DOUBLE_EQ(c->pitchMm, 10);
  EXPECT_EQ(c->text(), "chessboard:11x8:10");
  const auto pts = c->platePoints();
  ASSERT_EQ(pts.size(), 88u);
  EXPECT_DOUBLE_EQ(pts[12].x, 10);
  EXPECT_DOUBLE_EQ(pts[12].y, 10);
  const auto d = parseBoardSpec("circles:9x7:12:6", why);
  ASSERT_TRUE(d) << why;
  EXPECT_DOUBLE_EQ(d->diameterMm, 6);
}

TEST(BoardSpec, RefusesWithAReason) {
  for (const char* bad :
       {"", "chessboard", "chessboard:11x8", "chessboard:11-8:10", "chessboard:11x8:-1",
        "chessboard:11x8:abc", "chessboard:10x8:5", "circles:9x7:12", "circles:9x7:12:12",
        "hexagons:3x3:1", "chessboard:1x8:10", "chessboard:11x8:10:3"}) {
    std::string why;
    EXPECT_FALSE(parseBoardSpec(bad, why)) << bad;
    EXPECT_FALSE(why.empty()) << bad;
  }
}

}  // namespace
}  // namespace facet
