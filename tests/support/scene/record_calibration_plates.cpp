// Renders the example station's calibration plate images (recipes/calibration_plates): the demo
// camera (640x480, f = 2400 px, slight barrel distortion) looking at an 11x8-corner chessboard
// of 2 mm squares in 12 poses tilted 20-38 degrees over the whole field, and once lying flat where
// the demo parts lie, 120 mm in front of the camera (0.05 mm per pixel, the scale the demo was
// recorded at). `facet calibrate` turns them into recipes/calibration.yaml (see recipes/README.md).
//
// Usage: record_calibration_plates OUTPUT_FOLDER
#include <cstdio>
#include <filesystem>
#include <string>

#include <opencv2/imgcodecs.hpp>

#include "tests/support/scene/calibration_plates.hpp"

int main(int argc, char** argv) {
  using namespace facet::scene;
  if (argc != 2) {
    std::fprintf(stderr, "usage: record_calibration_plates OUTPUT_FOLDER\n");
    return 1;
  }
  const std::filesystem::path out = argv[1];
  std::filesystem::create_directories(out / "views");
  LensCamera camera;
  camera.size = {640, 480};
  camera.fx = camera.fy = 2400;
  camera.cx = 319.5, camera.cy = 239.5;
  camera.k1 = -0.012, camera.k2 = 0.004;
  const int cols = 11, rows = 8;
  const double pitch = 2.0;
  const auto render = [&](const PlanePlacement& placement, std::uint64_t seed) {
    PlaneScene s;
    s.camera = camera;
    s.placement = placement;
    addChessboardPlate(s, cols, rows, pitch);
    s.lensBlurSigma = 0.6;
    s.noiseSigma = 1.5;
    s.seed = seed;
    return s.render();
  };
  // Twelve views that together cover the field (a lens model is only known where the views
  // put points): the plate 150 mm away, shifted over a 3x3 grid of the image and tilted 20-35
  // degrees about a turning axis, plus three steeper views in the middle.
  const double distance = 150;
  int i = 0;
  for (int gy = -1; gy <= 1; ++gy)
    for (int gx = -1; gx <= 1; ++gx, ++i) {
      const double tilt = 20 + 15 * ((i * 7) % 9) / 8.0;
      const auto placement =
          lookAtPlane({(cols - 1) * pitch / 2, (rows - 1) * pitch / 2}, distance, tilt, 40.0 * i,
                      6.0 * (i % 3 - 1), camera, {gx * 120.0, gy * 90.0});
      char name[32];
      std::snprintf(name, sizeof name, "plate_%02d.png", i);
      cv::imwrite((out / "views" / name).string(), render(placement, 100 + i));
    }
  for (; i < 12; ++i) {
    const auto placement = lookAtPlane({(cols - 1) * pitch / 2, (rows - 1) * pitch / 2}, distance,
                                       38, 120.0 * i, 0, camera);
    char name[32];
    std::snprintf(name, sizeof name, "plate_%02d.png", i);
    cv::imwrite((out / "views" / name).string(), render(placement, 100 + i));
  }
  const auto flat =
      lookAtPlane({(cols - 1) * pitch / 2, (rows - 1) * pitch / 2}, 120, 0, 0, 0, camera);
  cv::imwrite((out / "plane.png").string(), render(flat, 99));
  std::printf("wrote %s\n", out.string().c_str());
  return 0;
}
