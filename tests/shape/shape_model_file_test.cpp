// Shape model files: round trip, and every way a file can be bad.
#include <cstring>
#include <filesystem>
#include <fstream>
#include <functional>
#include <iterator>
#include <limits>
#include <string>
#include <vector>

#include <gtest/gtest.h>
#include <opencv2/imgproc.hpp>

#include "algorithms/shape/find_shape_model.hpp"
#include "algorithms/shape/shape_model_file.hpp"
#include "tests/shape/bracket_scenes.hpp"
#include "tests/shape/test_photos.hpp"

namespace facet {
namespace {

namespace fs = std::filesystem;

class ShapeModelFile : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ =
        fs::temp_directory_path() /
        ("facet_shape_file_" + std::to_string(::testing::UnitTest::GetInstance()->random_seed()) +
         "_" + ::testing::UnitTest::GetInstance()->current_test_info()->name());
    fs::create_directories(dir_);
  }
  void TearDown() override { fs::remove_all(dir_); }

  std::vector<char> bytesOf(const fs::path& p) {
    std::ifstream in(p, std::ios::binary);
    return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
  }
  void write(const fs::path& p, const std::vector<char>& bytes) {
    std::ofstream out(p, std::ios::binary | std::ios::trunc);
    out.write(bytes.data(), static_cast<std::streamsize>(bytes.size()));
  }
  // The error loadShapeModel gives for `p`; fails the test if it loads.
  std::string loadError(const fs::path& p) {
    try {
      loadShapeModel(p);
    } catch (const ShapeModelFileError& e) {
      return e.what();
    }
    ADD_FAILURE() << p << " should have been refused";
    return {};
  }

  fs::path dir_;
};

TEST_F(ShapeModelFile, RoundTripKeepsEverything) {
  ShapeModelParams params;
  params.scaleMin = 0.9;
  params.scaleMax = 1.1;
  params.angleStart = radians(-45.0);
  params.angleExtent = radians(90.0);
  const ShapeModel model = createShapeModel(testing::bracketTemplate(), params);
  const fs::path file = dir_ / "part.model";
  saveShapeModel(model, file);
  const ShapeModel loaded = loadShapeModel(file);

  EXPECT_EQ(loaded.templateSize, model.templateSize);
  EXPECT_EQ(loaded.referencePoint, model.referencePoint);
  EXPECT_EQ(loaded.angleStart, model.angleStart);
  EXPECT_EQ(loaded.angleExtent, model.angleExtent);
  EXPECT_EQ(loaded.scaleMin, model.scaleMin);
  EXPECT_EQ(loaded.scaleMax, model.scaleMax);
  EXPECT_EQ(loaded.minContrast, model.minContrast);
  EXPECT_EQ(loaded.contrastHigh, model.contrastHigh);
  ASSERT_EQ(loaded.numLevels(), model.numLevels());
  for (int l = 0; l < model.numLevels(); ++l) {
    EXPECT_EQ(loaded.levels[l].angleStep, model.levels[l].angleStep);
    EXPECT_EQ(loaded.levels[l].scaleStep, model.levels[l].scaleStep);
    ASSERT_EQ(loaded.levels[l].points.size(), model.levels[l].points.size());
    for (std::size_t i = 0; i < model.levels[l].points.size(); ++i) {
      EXPECT_EQ(loaded.levels[l].points[i].position, model.levels[l].points[i].position);
      EXPECT_EQ(loaded.levels[l].points[i].direction, model.levels[l].points[i].direction);
    }
  }
  ASSERT_EQ(loaded.finePoints.size(), model.finePoints.size());
  EXPECT_EQ(loaded.finePoints.back().position, model.finePoints.back().position);

  // The loaded model finds exactly what the trained one finds.
  const Pose2D truth{200.2, 150.9, radians(12.0), 1.03};
  const cv::Mat image = testing::bracketScene({400, 300}, {truth}, 5);
  const auto a = findShapeModel(image, model);
  const auto b = findShapeModel(image, loaded);
  ASSERT_EQ(a.size(), 1u);
  ASSERT_EQ(b.size(), 1u);
  EXPECT_EQ(a[0].x, b[0].x);
  EXPECT_EQ(a[0].angle, b[0].angle);
  EXPECT_EQ(a[0].scale, b[0].scale);
}

// The same payload under another header: `version`, and the payload changed by `edit`, with a
// size and checksum that fit it (what an older facet or a careful hand would have written).
std::vector<char> rewritten(const std::vector<char>& file, std::uint32_t version,
                            const std::function<void(std::vector<char>&)>& edit) {
  constexpr std::size_t kHeader = 8 + 4 + 8;
  std::vector<char> payload(file.begin() + kHeader, file.end() - 8);
  edit(payload);
  std::vector<char> out(file.begin(), file.begin() + 8);
  const auto append = [&out](const auto& v) {
    const auto* p = reinterpret_cast<const char*>(&v);
    out.insert(out.end(), p, p + sizeof(v));
  };
  append(version);
  append(static_cast<std::uint64_t>(payload.size()));
  out.insert(out.end(), payload.begin(), payload.end());
  std::uint64_t h = 14695981039346656037ull;  // FNV-1a, as the format says
  for (const char c : payload) h = (h ^ static_cast<unsigned char>(c)) * 1099511628211ull;
  append(h);
  return out;
}

// The bytes a model's tracked periods take at the end of a version 4 payload.
std::size_t periodBlockSize(const ShapeModel& model) {
  return sizeof(std::uint32_t) + model.trackedPeriods.size() * 3 * sizeof(double);
}

// The bytes a model's near-symmetries take before them (at the end of a version 3 payload).
std::size_t symmetryBlockSize(const ShapeModel& model) {
  return sizeof(std::uint32_t) + model.symmetries.size() * 4 * sizeof(double);
}

// A cross whose arms differ by a few pixels: its quarter turns are near-symmetries.
cv::Mat crossTemplate() {
  cv::Mat image(134, 140, CV_8UC1, cv::Scalar(40));
  const std::vector<cv::Point> cross = {{81, 9},  {81, 56},  {130, 56}, {130, 78},
                                        {81, 78}, {81, 122}, {59, 122}, {59, 78},
                                        {13, 78}, {13, 56},  {59, 56},  {59, 12}};
  cv::fillPoly(image, std::vector<std::vector<cv::Point>>{cross}, cv::Scalar(200), cv::LINE_AA);
  cv::GaussianBlur(image, image, {0, 0}, 1.0);
  return image;
}

TEST_F(ShapeModelFile, SymmetriesAreKeptAndFilesWithoutThemFindThemAtLoad) {
  const ShapeModel model = createShapeModel(crossTemplate());
  ASSERT_GE(model.symmetries.size(), 2u);  // the quarter turns at least
  const fs::path file = dir_ / "cross.model";
  saveShapeModel(model, file);
  const auto same = [&](const ShapeModel& loaded, const char* what) {
    ASSERT_EQ(loaded.symmetries.size(), model.symmetries.size()) << what;
    for (std::size_t i = 0; i < model.symmetries.size(); ++i) {
      EXPECT_EQ(loaded.symmetries[i].angle, model.symmetries[i].angle) << what;
      EXPECT_EQ(loaded.symmetries[i].centre, model.symmetries[i].centre) << what;
      EXPECT_EQ(loaded.symmetries[i].score, model.symmetries[i].score) << what;
    }
  };
  same(loadShapeModel(file), "version 4");
  // Version 2 ended after the estimator byte: the same symmetries, found at load.
  const std::size_t periodBytes = periodBlockSize(model);
  const fs::path v2 = dir_ / "version2.model";
  write(v2, rewritten(bytesOf(file), 2, [&](std::vector<char>& p) {
          p.resize(p.size() - periodBytes - symmetryBlockSize(model));
        }));
  same(loadShapeModel(v2), "version 2");

  // Values no search can use behind a valid checksum: a turn that is not a number, more turns
  // than any model has.
  const fs::path nan = dir_ / "nan_symmetry.model";
  write(nan, rewritten(bytesOf(file), kShapeModelFileVersion, [&](std::vector<char>& p) {
          const double bad = std::numeric_limits<double>::quiet_NaN();
          std::memcpy(
              p.data() + p.size() - periodBytes - symmetryBlockSize(model) + sizeof(std::uint32_t),
              &bad, sizeof bad);
        }));
  std::string e = loadError(nan);
  EXPECT_NE(e.find("symmetry"), std::string::npos) << e;
  const fs::path many = dir_ / "many_symmetries.model";
  write(many, rewritten(bytesOf(file), kShapeModelFileVersion, [&](std::vector<char>& p) {
          const std::uint32_t count = 1000;
          std::memcpy(p.data() + p.size() - periodBytes - symmetryBlockSize(model), &count,
                      sizeof count);
        }));
  e = loadError(many);
  EXPECT_NE(e.find("symmetry count"), std::string::npos) << e;
}

// A patch of a chessboard photographed at a slant (tests/data/photos/slanted_board_template.png)
// has periods its top level cannot tell apart (model_symmetry.hpp, findTrackedPeriods).
TEST_F(ShapeModelFile, TrackedPeriodsAreKeptAndFilesWithoutThemFindThemAtLoad) {
  const cv::Mat templ = testing::testPhoto("slanted_board_template.png");
  ASSERT_FALSE(templ.empty());
  const ShapeModel model = createShapeModel(templ);
  ASSERT_FALSE(model.trackedPeriods.empty());
  const fs::path file = dir_ / "board.model";
  saveShapeModel(model, file);
  const auto same = [&](const ShapeModel& loaded, const char* what) {
    ASSERT_EQ(loaded.trackedPeriods.size(), model.trackedPeriods.size()) << what;
    for (std::size_t i = 0; i < model.trackedPeriods.size(); ++i) {
      EXPECT_EQ(loaded.trackedPeriods[i].shift, model.trackedPeriods[i].shift) << what;
      EXPECT_EQ(loaded.trackedPeriods[i].score, model.trackedPeriods[i].score) << what;
    }
  };
  same(loadShapeModel(file), "version 4");
  // Version 3 ended after the symmetries: the same periods, found at load.
  const std::size_t periodBytes = periodBlockSize(model);
  const fs::path v3 = dir_ / "version3.model";
  write(v3, rewritten(bytesOf(file), 3,
                      [&](std::vector<char>& p) { p.resize(p.size() - periodBytes); }));
  same(loadShapeModel(v3), "version 3");

  // Values no search can use behind a valid checksum: a shift that is not a number, more periods
  // than any model has.
  const fs::path nan = dir_ / "nan_period.model";
  write(nan, rewritten(bytesOf(file), kShapeModelFileVersion, [&](std::vector<char>& p) {
          const double bad = std::numeric_limits<double>::quiet_NaN();
          std::memcpy(p.data() + p.size() - periodBytes + sizeof(std::uint32_t), &bad, sizeof bad);
        }));
  std::string e = loadError(nan);
  EXPECT_NE(e.find("period"), std::string::npos) << e;
  const fs::path many = dir_ / "many_periods.model";
  write(many, rewritten(bytesOf(file), kShapeModelFileVersion, [&](std::vector<char>& p) {
          const std::uint32_t count = 1000;
          std::memcpy(p.data() + p.size() - periodBytes, &count, sizeof count);
        }));
  e = loadError(many);
  EXPECT_NE(e.find("period count"), std::string::npos) << e;
}

TEST_F(ShapeModelFile, TheEdgeEstimatorIsKeptAndVersionOneFilesLoadAsTheProfileFit) {
  ShapeModelParams params;
  params.edgeEstimator = EdgeEstimator::FacetZeroCrossing;
  const ShapeModel model = createShapeModel(testing::bracketTemplate(), params);
  const fs::path file = dir_ / "zero_crossing.model";
  saveShapeModel(model, file);
  EXPECT_EQ(loadShapeModel(file).edgeEstimator, EdgeEstimator::FacetZeroCrossing);

  // Version 1 had no estimator byte after the subpixel points (nor the symmetries and periods
  // that follow it since versions 3 and 4): its models used the profile fit.
  const std::size_t symmetryBytes = symmetryBlockSize(model) + periodBlockSize(model);
  const fs::path old = dir_ / "version1.model";
  write(old, rewritten(bytesOf(file), 1,
                       [&](std::vector<char>& p) { p.resize(p.size() - symmetryBytes - 1); }));
  const ShapeModel loaded = loadShapeModel(old);
  EXPECT_EQ(loaded.edgeEstimator, EdgeEstimator::ProfileFit);
  EXPECT_EQ(loaded.finePoints.size(), model.finePoints.size());

  const fs::path unknown = dir_ / "estimator7.model";
  write(unknown, rewritten(bytesOf(file), kShapeModelFileVersion,
                           [&](std::vector<char>& p) { p[p.size() - symmetryBytes - 1] = 7; }));
  const std::string e = loadError(unknown);
  EXPECT_NE(e.find("edge estimator"), std::string::npos) << e;
}

TEST_F(ShapeModelFile, BadFilesAreRefusedNamingTheFile) {
  const fs::path good = dir_ / "good.model";
  saveShapeModel(createShapeModel(testing::bracketTemplate()), good);
  const std::vector<char> bytes = bytesOf(good);
  ASSERT_GT(bytes.size(), 1000u);

  const fs::path missing = dir_ / "missing.model";
  EXPECT_NE(loadError(missing).find(missing.string()), std::string::npos);

  const fs::path truncated = dir_ / "truncated.model";
  write(truncated, std::vector<char>(bytes.begin(), bytes.begin() + bytes.size() / 2));
  std::string e = loadError(truncated);
  EXPECT_NE(e.find(truncated.string()), std::string::npos) << e;
  EXPECT_NE(e.find("truncated"), std::string::npos) << e;

  const fs::path headerOnly = dir_ / "header.model";
  write(headerOnly, std::vector<char>(bytes.begin(), bytes.begin() + 10));
  EXPECT_NE(loadError(headerOnly).find("truncated"), std::string::npos);

  const fs::path corrupt = dir_ / "corrupt.model";
  std::vector<char> flipped = bytes;
  flipped[bytes.size() / 2] ^= 0x5a;
  write(corrupt, flipped);
  e = loadError(corrupt);
  EXPECT_NE(e.find(corrupt.string()), std::string::npos) << e;
  EXPECT_NE(e.find("checksum"), std::string::npos) << e;

  const fs::path version = dir_ / "version.model";
  std::vector<char> newer = bytes;
  newer[8] = 99;  // the version follows the 8-byte magic
  write(version, newer);
  e = loadError(version);
  EXPECT_NE(e.find(version.string()), std::string::npos) << e;
  EXPECT_NE(e.find("version 99"), std::string::npos) << e;

  const fs::path other = dir_ / "other.png";
  write(other, {'\x89', 'P', 'N', 'G', '\r', '\n', '\x1a', '\n', 0, 0, 0, 0});
  EXPECT_NE(loadError(other).find("not a facet shape model"), std::string::npos);

  const fs::path empty = dir_ / "empty.model";
  write(empty, {});
  EXPECT_NE(loadError(empty).find(empty.string()), std::string::npos);

  const fs::path trailing = dir_ / "trailing.model";
  std::vector<char> longer = bytes;
  longer.push_back('x');
  write(trailing, longer);
  EXPECT_NE(loadError(trailing).find("corrupt"), std::string::npos);

  EXPECT_THROW(saveShapeModel(ShapeModel{}, dir_ / "empty_model.model"), ShapeModelFileError);
  EXPECT_THROW(saveShapeModel(loadShapeModel(good), dir_ / "no_such_dir" / "x.model"),
               ShapeModelFileError);
}

// A file with a valid checksum can still hold values the search cannot use (hand-made, or
// damaged before it was written). Found while writing the loader's fuzz target: a zero or tiny
// angle step makes findShapeModel convert an infinite sample count to int (or allocate without
// bound), NaN points reach pixel indices.
TEST_F(ShapeModelFile, UnusableValuesBehindAValidChecksumAreRefused) {
  const ShapeModel trained = createShapeModel(testing::bracketTemplate());
  const auto refusal = [&](const char* name, auto&& spoil) {
    ShapeModel m = trained;
    spoil(m);
    const fs::path file = dir_ / (std::string(name) + ".model");
    saveShapeModel(m, file);
    const std::string e = loadError(file);
    EXPECT_NE(e.find(file.string()), std::string::npos) << e;
    EXPECT_NE(e.find("invalid values"), std::string::npos) << name << ": " << e;
  };
  const double nan = std::numeric_limits<double>::quiet_NaN();
  refusal("zero_angle_step", [](ShapeModel& m) { m.levels.back().angleStep = 0.0; });
  refusal("tiny_angle_step", [](ShapeModel& m) { m.levels.front().angleStep = 1e-300; });
  refusal("nan_angle_step", [&](ShapeModel& m) { m.levels.front().angleStep = nan; });
  refusal("negative_scale_step", [](ShapeModel& m) { m.levels.front().scaleStep = -1.0; });
  refusal("nan_reference", [&](ShapeModel& m) { m.referencePoint.x = nan; });
  refusal("infinite_contrast",
          [](ShapeModel& m) { m.minContrast = std::numeric_limits<double>::infinity(); });
  refusal("angle_extent", [](ShapeModel& m) { m.angleExtent = 100.0; });
  refusal("template_size", [](ShapeModel& m) { m.templateSize = {0, 10}; });
  refusal("nan_point", [](ShapeModel& m) {
    m.levels.front().points.front().position.x = std::numeric_limits<float>::quiet_NaN();
  });
  refusal("far_point", [](ShapeModel& m) { m.finePoints.back().position.y = 1e30f; });
  // A point far off the template with a large scale made the search allocate 284 GB for its
  // border (found by the fuzz target).
  refusal("point_off_template", [](ShapeModel& m) { m.levels.back().points[0].position.x = 9e4f; });
  refusal("huge_scale", [](ShapeModel& m) { m.scaleMax = 1e6; });
  refusal("far_reference", [](ShapeModel& m) { m.referencePoint.x = 1e9; });
  refusal("angle_start", [](ShapeModel& m) { m.angleStart = 1e43; });
  refusal("huge_angle_step", [](ShapeModel& m) { m.levels.front().angleStep = 2.7e154; });
  // Level 0's step 1/2,750 of level 1's: the search's wider look on level 0 spans two steps of
  // level 1 in level 0's steps, and one search of a 48x40 image took six minutes (fuzz target).
  refusal("fine_level_below_a_coarse_one",
          [](ShapeModel& m) { m.levels.front().angleStep = m.levels[1].angleStep / 2750.0; });
  // The trained model itself is fine.
  saveShapeModel(trained, dir_ / "trained.model");
  EXPECT_NO_THROW(loadShapeModel(dir_ / "trained.model"));
}

}  // namespace
}  // namespace facet
