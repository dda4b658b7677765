// facet calibrate: camera calibration from plate images (algorithms/calibration), written as the
// station's calibration file (config/calibration_file.hpp).
#include <algorithm>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <set>

#include "algorithms/calibration/camera_calibration.hpp"
#include "camera/image_codecs.hpp"
#include "config/calibration_file.hpp"
#include "service/cli/calibration_report.hpp"
#include "service/cli/command_line.hpp"

namespace facet::cli {
namespace {

struct CalibrateOptions {
  std::string images, board, plane, out, report;
  double planeOffsetMm = 0;
  CalibrationOptions limits;
  bool json = false;
};

std::vector<std::filesystem::path> imageFiles(const std::string& folder) {
  std::error_code ec;
  if (!std::filesystem::is_directory(folder, ec))
    throw InputError(folder + ": no such folder (--images)");
  static const std::set<std::string> extensions{".png", ".bmp", ".tif", ".tiff",
                                                ".pgm", ".jpg", ".jpeg"};
  std::vector<std::filesystem::path> files;
  for (const auto& entry : std::filesystem::directory_iterator(folder, ec)) {
    std::string ext = entry.path().extension().string();
    std::transform(ext.begin(), ext.end(), ext.begin(),
                   [](unsigned char c) { return std::tolower(c); });
    if (entry.is_regular_file() && extensions.count(ext)) files.push_back(entry.path());
  }
  std::sort(files.begin(), files.end());
  if (files.empty())
    throw InputError(folder + ": no images (png, bmp, tif, pgm, jpg) in the folder");
  return files;
}

std::string sizeText(cv::Size s) {
  return std::to_string(s.width) + "x" + std::to_string(s.height);
}

cv::Mat readGrey(const std::filesystem::path& file) {
  return readImage(file, cv::IMREAD_GRAYSCALE | cv::IMREAD_ANYDEPTH);
}

nlohmann::json matrixJson(const cv::Matx33d& m) {
  nlohmann::json rows = nlohmann::json::array();
  for (int r = 0; r < 3; ++r) rows.push_back({m(r, 0), m(r, 1), m(r, 2)});
  return rows;
}

nlohmann::json viewsJson(const CameraCalibration& c) {
  nlohmann::json views = nlohmann::json::array();
  for (const auto& v : c.views) {
    views.push_back({{"file", v.name},
                     {"rms_px", v.used ? nlohmann::json(v.rmsPx) : nlohmann::json()},
                     {"used", v.used},
                     {"why", v.status.message}});
    if (!v.note.empty()) views.back()["note"] = v.note;
    if (v.status.ok()) views.back()["points"] = v.points.size();
  }
  return views;
}

[[noreturn]] void refuse(const CalibrateOptions& o, const CameraCalibration& c,
                         const std::string& why) {
  if (o.json) {
    printJson(
        {{"error", {{"cause", "calibration_refused"}, {"message", why}}}, {"views", viewsJson(c)}});
  } else {
    for (const auto& v : c.views)
      if (!v.used && !v.status.message.empty())
        std::cerr << v.name << ": " << v.status.message << "\n";
    std::cerr << "facet: calibration_refused: " << why << "\n";
  }
  std::cout.flush();
  std::exit(2);
}

void run(const CalibrateOptions& o) {
  std::string why;
  const auto board = parseBoardSpec(o.board, why);
  if (!board) throw InputError("--board: " + why);
  if (o.out.empty()) throw InputError("--out: a calibration file name is needed");
  const auto files = imageFiles(o.images);

  // Every image is read (and its size checked) first; the readable ones are then searched for
  // the plate together.
  std::vector<cv::Mat> images;
  std::vector<std::string> names;
  cv::Size size;
  std::string sizeFrom;
  for (const auto& file : files) {
    const cv::Mat image = readGrey(file);
    const std::string name = file.filename().string();
    if (!image.empty() && size.empty()) {
      size = image.size();
      sizeFrom = name;
    } else if (!image.empty() && image.size() != size) {
      throw InputError(file.string() + ": the image is " + sizeText(image.size()) + " but " +
                       sizeFrom + " is " + sizeText(size) +
                       "; all calibration images must come from the same camera at one resolution");
    }
    images.push_back(image);
    names.push_back(name);
  }
  const std::vector<PlateView> views = detectPlates(images, *board, names);
  if (size.empty()) throw InputError(o.images + ": none of the images could be read");

  CameraCalibration c = calibrateCamera(*board, size, views, o.limits);
  if (!c.status.ok()) refuse(o, c, c.status.message);

  config::CalibrationData data;
  data.board = board->text();
  data.camera = c.camera;
  data.rmsPx = c.rmsPx;
  std::optional<WorldMapping> mapping;
  if (!o.plane.empty()) {
    const cv::Mat image = readGrey(o.plane);
    if (image.empty()) throw InputError(o.plane + ": cannot read the plane image (--plane)");
    if (image.size() != size)
      throw InputError(o.plane + ": the plane image is " + sizeText(image.size()) +
                       " but the calibration images are " + sizeText(size));
    PlanePose pose;
    const PlateView view =
        detectPlate(image, *board, std::filesystem::path(o.plane).filename().string());
    if (const auto plane = estimatePlanePose(*board, c.camera, view, o.planeOffsetMm, pose);
        !plane.ok())
      refuse(o, c, "--plane " + plane.message);
    data.plane = pose;
    mapping.emplace(c.camera, pose);
    data.mmPerPixel = mapping->mmPerPixelAt({(size.width - 1) / 2.0, (size.height - 1) / 2.0});
  }
  const std::string comment =
      "facet calibrate --board " + board->text() + " from " +
      std::to_string(
          std::count_if(c.views.begin(), c.views.end(), [](const ViewFit& v) { return v.used; })) +
      " views in " + o.images + ", distortion terms " + c.distortionModel +
      (o.plane.empty() ? "" : "\nmeasuring plane from " + o.plane);
  {
    std::ofstream out(o.out);
    out << config::calibrationFileText(data, comment);
    if (!out) throw InputError(o.out + ": cannot write the calibration file");
  }
  if (!o.report.empty()) writeCalibrationReport(o.report, *board, size, c, data);

  if (o.json) {
    const cv::Mat& d = c.camera.distortion;
    nlohmann::json j{{"rms_px", c.rmsPx},
                     {"camera_matrix", matrixJson(c.camera.cameraMatrix)},
                     {"distortion", std::vector<double>(d.begin<double>(), d.end<double>())},
                     {"distortion_model", c.distortionModel},
                     {"image_size", {size.width, size.height}},
                     {"coverage", c.coverage},
                     {"views", viewsJson(c)},
                     {"out", o.out}};
    if (!c.warning.empty()) j["warning"] = c.warning;
    for (const auto& m : c.distortionCandidates)
      j["distortion_models"].push_back({{"terms", m.terms}, {"rms_px", m.rmsPx}, {"bic", m.bic}});
    if (data.plane)
      j["plane"] = {{"rotation", matrixJson(data.plane->rotation)},
                    {"translation_mm",
                     {data.plane->translationMm[0], data.plane->translationMm[1],
                      data.plane->translationMm[2]}},
                    {"offset_mm", data.plane->offsetMm},
                    {"mm_per_px", data.mmPerPixel}};
    printJson(j);
    return;
  }
  for (const auto& v : c.views) {
    if (v.used)
      std::cout << v.name << ": used, RMS " << v.rmsPx << " px"
                << (v.note.empty() ? "" : " (" + v.note + ")") << "\n";
    else
      std::cout << v.name << ": not used: " << v.status.message << "\n";
  }
  if (!c.warning.empty()) std::cerr << "facet: warning: " << c.warning << "\n";
  std::cout << "RMS reprojection error " << c.rmsPx << " px, field covered "
            << static_cast<int>(100 * c.coverage + 0.5) << "%\n"
            << "fx " << c.camera.cameraMatrix(0, 0) << " fy " << c.camera.cameraMatrix(1, 1)
            << " cx " << c.camera.cameraMatrix(0, 2) << " cy " << c.camera.cameraMatrix(1, 2)
            << ", distortion terms " << c.distortionModel << "\n";
  if (data.plane)
    std::cout << "measuring plane: " << data.mmPerPixel << " mm per pixel at the image centre\n";
  std::cout << "wrote " << o.out << "\n";
}

}  // namespace

void addCalibrateCommand(CLI::App& app) {
  auto options = std::make_shared<CalibrateOptions>();
  auto* cmd = app.add_subcommand("calibrate", "Calibrate the camera from images of a plate");
  cmd->add_option("--images", options->images, "Folder of plate images (one camera, one size)")
      ->required();
  cmd->add_option("--board", options->board,
                  "chessboard:COLSxROWS:SQUARE_MM (inner corners), "
                  "circles:COLSxROWS:PITCH_MM:DIAMETER_MM or "
                  "charuco:COLSxROWS:SQUARE_MM:MARKER_MM:DICT (squares, e.g. DICT_5X5_100)")
      ->required();
  cmd->add_option("--plane", options->plane, "Image of the plate lying where the parts lie");
  cmd->add_option("--plane-offset-mm", options->planeOffsetMm,
                  "Height of the measured face above the plate's surface, mm (default 0)");
  cmd->add_option("--out", options->out, "Calibration file to write")->required();
  cmd->add_option("--report", options->report,
                  "HTML page with residuals, per-view errors, coverage");
  cmd->add_option("--min-views", options->limits.minViews, "Fewest usable views (default 8)")
      ->check(CLI::Range(3, 1000));
  cmd->add_option("--max-rms-px", options->limits.maxRmsPx,
                  "Largest accepted RMS reprojection error, px (default 0.5)")
      ->check(CLI::PositiveNumber);
  cmd->add_option("--min-coverage", options->limits.minCoverage,
                  "Smallest accepted covered share of the image, 0..1 (default 0.25)")
      ->check(CLI::Range(0.0, 1.0));
  cmd->add_flag("--json", options->json, "Print one JSON object");
  cmd->callback([options] { run(*options); });
}

}  // namespace facet::cli
