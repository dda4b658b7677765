// The station's calibration file: facet's format round trip, the scale-only form, OpenCV files,
// and bad files reported at their line.
#include "config/calibration_file.hpp"

#include <filesystem>
#include <fstream>

#include <gtest/gtest.h>
#include <unistd.h>
#include <opencv2/calib3d.hpp>

namespace facet::config {
namespace {

class CalibrationFileTest : public ::testing::Test {
 protected:
  std::filesystem::path dir =
      std::filesystem::temp_directory_path() / ("facet-calfile-" + std::to_string(::getpid()));
  void SetUp() override { std::filesystem::create_directories(dir); }
  void TearDown() override { std::filesystem::remove_all(dir); }
  std::filesystem::path write(const std::string& name, const std::string& text) {
    std::ofstream(dir / name) << text;
    return dir / name;
  }
};

CalibrationData sample() {
  CalibrationData d;
  CameraModel c;
  c.cameraMatrix = {1500.25, 0, 645.125, 0, 1501.5, 508.75, 0, 0, 1};
  c.distortion = (cv::Mat_<double>(1, 5) << -0.22, 0.08, 0.0012, -0.0008, 0.001);
  c.imageSize = {1280, 1024};
  d.camera = c;
  PlanePose p;
  cv::Mat R;
  cv::Rodrigues(cv::Vec3d(0.2, -0.3, 0.1), R);
  p.rotation = cv::Matx33d(R);
  p.translationMm = {-50.5, -40.25, 300.125};
  p.offsetMm = 2.5;
  d.plane = p;
  d.mmPerPixel = 0.2;
  d.rmsPx = 0.0123;
  d.board = "chessboard:11x8:10";
  return d;
}

TEST_F(CalibrationFileTest, RoundTripKeepsEveryNumber) {
  const auto file = write("cal.yaml", calibrationFileText(sample(), "made by a test\nsecond line"));
  Diagnostics out;
  const auto d = readCalibrationFile(file, out);
  ASSERT_TRUE(d) << out.text();
  EXPECT_EQ(d->kind(), "lens model + plane");
  EXPECT_EQ(d->camera->imageSize, cv::Size(1280, 1024));
  EXPECT_EQ(d->camera->cameraMatrix(0, 2), 645.125);
  EXPECT_EQ(d->camera->distortion.at<double>(4), 0.001);
  EXPECT_EQ(d->plane->rotation(1, 2), sample().plane->rotation(1, 2));
  EXPECT_EQ(d->plane->translationMm[2], 300.125);
  EXPECT_EQ(d->plane->offsetMm, 2.5);
  EXPECT_EQ(d->mmPerPixel, 0.2);
  EXPECT_EQ(d->board, "chessboard:11x8:10");
}

TEST_F(CalibrationFileTest, ScaleAloneIsValidAndSaysSo) {
  Diagnostics out;
  const auto d = readCalibrationFile(
      write("s.yaml", "format: facet-calibration 1\nmm_per_pixel: 0.05\n"), out);
  ASSERT_TRUE(d) << out.text();
  EXPECT_EQ(d->kind(), "scale only, no lens model");
  EXPECT_EQ(d->mmPerPixel, 0.05);
}

TEST_F(CalibrationFileTest, OpenCvFileStorageFilesAreStillRead) {
  Diagnostics out;
  const auto d = readCalibrationFile(
      std::filesystem::path(FACET_SOURCE_DIR) / "tests/fuzz/calibration/corpus/opencv.yaml", out);
  ASSERT_TRUE(d) << out.text();
  EXPECT_EQ(d->camera->cameraMatrix(0, 0), 2400.0);
  EXPECT_EQ(d->kind(), "lens model, scale only");
}

// An OpenCV matrix whose header asks for a huge size (a byte for `cols`: OpenCV allocated 17 GB
// for it) is refused before OpenCV reads it; a matrix of a sane size but too big for a
// calibration likewise.
TEST_F(CalibrationFileTest, OpenCvMatrixOfAHugeOrNonNumericSizeIsRefused) {
  Diagnostics out;
  EXPECT_FALSE(readCalibrationFile(std::filesystem::path(FACET_SOURCE_DIR) /
                                       "tests/fuzz/calibration/regressions/"
                                       "opencv_matrix_cols_not_a_number.yaml",
                                   out));
  EXPECT_NE(out.text().find("'distortion_coefficients' is not a small matrix"), std::string::npos)
      << out.text();
  // A sane size too big for a calibration, and rows * cols beyond a 64-bit integer (found by
  // the fuzzer: the product overflowed).
  for (const char* size :
       {"rows: 100000\n   cols: 100000", "rows: 2\n   cols: 7791680384683591452"}) {
    const auto file =
        write("big.yaml", std::string("%YAML:1.0\n---\ncamera_matrix: !!opencv-matrix\n   ") +
                              size + "\n   dt: d\n   data: [ 1. ]\n");
    Diagnostics bigOut;
    EXPECT_FALSE(readCalibrationFile(file, bigOut)) << size;
    EXPECT_NE(bigOut.text().find("'camera_matrix' is not a small matrix"), std::string::npos)
        << size << ": " << bigOut.text();
  }
}

TEST_F(CalibrationFileTest, TruncatedFileIsReportedAtItsLine) {
  std::string text = calibrationFileText(sample(), "");
  text = text.substr(0, text.find("distortion:") + 18);  // cut inside the distortion list
  const auto file = write("cut.yaml", text);
  Diagnostics out;
  EXPECT_FALSE(readCalibrationFile(file, out));
  ASSERT_TRUE(out.hasErrors());
  EXPECT_NE(out.text().find(file.string() + ":"), std::string::npos) << out.text();
  EXPECT_GT(out.items().front().where.line, 0) << out.text();
}

TEST_F(CalibrationFileTest, WrongMatrixShapeIsReportedAtTheMatrix) {
  const auto file = write("shape.yaml",
                          "format: facet-calibration 1\n"
                          "image_size: [640, 480]\n"
                          "camera_matrix: [[800, 0, 320], [0, 800, 240]]\n"
                          "distortion: [0, 0, 0, 0]\n"
                          "mm_per_pixel: 0.1\n");
  Diagnostics out;
  EXPECT_FALSE(readCalibrationFile(file, out));
  ASSERT_TRUE(out.hasErrors());
  EXPECT_EQ(out.items().front().where.line, 3) << out.text();
  EXPECT_NE(out.text().find("3 rows of 3 numbers"), std::string::npos) << out.text();
}

TEST_F(CalibrationFileTest, BadValuesAndUnknownKeysAreRefused) {
  for (const std::string body :
       {"mm_per_pixel: -1\n", "mm_per_pixel: 0.1\nlens: 3\n",
        "image_size: [640, 480]\ncamera_matrix: [[800, 0, 320], [0, 800, 240], [0, 0, 1]]\n"
        "distortion: [0, 0, 0]\n",
        "image_size: [640, 480]\ncamera_matrix: [[800, 0, 320], [0, 800, 240], [0, 0, 1]]\n"
        "distortion: [0, 0, 0, 0]\nplane: {rotation: [[2, 0, 0], [0, 1, 0], [0, 0, 1]], "
        "translation_mm: [0, 0, 100]}\n",
        "camera_matrix: [[800, 0, 320], [0, 800, 240], [0, 0, 1]]\ndistortion: [0, 0, 0, 0]\n", "",
        "mm_per_pixel: 0.1\nformat: facet-calibration 2\n"}) {
    const std::string text =
        body.find("format:") == std::string::npos ? "format: facet-calibration 1\n" + body : body;
    Diagnostics out;
    EXPECT_FALSE(readCalibrationFile(write("bad.yaml", text), out)) << text;
    EXPECT_TRUE(out.hasErrors()) << text;
  }
}

}  // namespace
}  // namespace facet::config
