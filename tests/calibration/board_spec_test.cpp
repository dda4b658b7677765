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

TEST(BoardSpec, ParsesACharucoBoardCountedInSquares) {
  std::string why;
  const auto b = parseBoardSpec("charuco:8x6:10:7:DICT_4X4_50", why);
  ASSERT_TRUE(b) << why;
  EXPECT_EQ(b->kind, BoardSpec::Kind::Charuco);
  EXPECT_TRUE(b->partialViews());
  // 8 x 6 squares have 7 x 5 inner corners: the pattern points.
  EXPECT_EQ(b->cols, 7);
  EXPECT_EQ(b->rows, 5);
  EXPECT_EQ(b->pointCount(), 35);
  EXPECT_DOUBLE_EQ(b->markerMm, 7);
  EXPECT_EQ(b->dictionary, 0);
  EXPECT_EQ(b->text(), "charuco:8x6:10:7:DICT_4X4_50");
  const auto pts = b->platePoints();
  EXPECT_DOUBLE_EQ(pts[8].x, 10);  // corner (1, 1)
  EXPECT_DOUBLE_EQ(pts[8].y, 10);
  // The dictionary's name in any case, with or without its prefix.
  const auto c = parseBoardSpec("charuco:12x9:15:11:5x5_100", why);
  ASSERT_TRUE(c) << why;
  EXPECT_EQ(dictionaryName(c->dictionary), "DICT_5X5_100");
  EXPECT_EQ(parseBoardSpec("charuco:5x5:10:7:dict_apriltag_36h11", why)->dictionary, 20);
}

TEST(BoardSpec, RefusesACharucoBoardItsDictionaryCannotFill) {
  std::string why;
  // 12 x 9 squares hold 54 markers; DICT_4X4_50 has 50.
  EXPECT_FALSE(parseBoardSpec("charuco:12x9:15:11:DICT_4X4_50", why));
  EXPECT_NE(why.find("54 markers"), std::string::npos) << why;
  EXPECT_FALSE(parseBoardSpec("charuco:8x6:10:7:DICT_9X9_50", why));
  EXPECT_NE(why.find("unknown ArUco dictionary"), std::string::npos) << why;
  EXPECT_NE(why.find("DICT_6X6_250"), std::string::npos) << why;  // the names to choose from
}

TEST(BoardSpec, RefusesWithAReason) {
  for (const char* bad :
       {"", "chessboard", "chessboard:11x8", "chessboard:11-8:10", "chessboard:11x8:-1",
        "chessboard:11x8:abc", "chessboard:10x8:5", "circles:9x7:12", "circles:9x7:12:12",
        "hexagons:3x3:1", "chessboard:1x8:10", "chessboard:11x8:10:3", "charuco:8x6:10:7",
        "charuco:8x6:10:10:DICT_4X4_50", "charuco:2x6:10:7:DICT_4X4_50",
        "charuco:8x6:10:0:DICT_4X4_50", "charuco:8x6:10:7:DICT_4X4_50:1"}) {
    std::string why;
    EXPECT_FALSE(parseBoardSpec(bad, why)) << bad;
    EXPECT_FALSE(why.empty()) << bad;
  }
}

}  // namespace
}  // namespace facet
