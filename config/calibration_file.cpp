#include "config/calibration_file.hpp"

#include <cmath>
#include <fstream>
#include <iomanip>
#include <iterator>
#include <set>
#include <sstream>

#include "config/yaml_document.hpp"

namespace facet::config {
namespace {

bool validDistortionCount(std::size_t n) {
  return n == 4 || n == 5 || n == 8 || n == 12 || n == 14;
}

class CalibrationReader {
 public:
  CalibrationReader(const std::filesystem::path& file, Diagnostics& out) : file_(file), out_(out) {}

  std::optional<CalibrationData> read() {
    const std::size_t before = out_.errorCount();
    const auto yaml = readYamlFile(file_, out_);
    if (!yaml) return std::nullopt;
    const YAML::Node& root = yaml->root;
    if (!root.IsMap()) {
      error(root, "a calibration file is a map of keys (format, camera_matrix, ...), not " +
                      describe(root));
      return std::nullopt;
    }
    static const std::set<std::string> known{"format", "board",         "image_size",
                                             "rms_px", "camera_matrix", "distortion",
                                             "plane",  "mm_per_pixel"};
    for (const auto& kv : root) {
      const std::string key = kv.first.Scalar();
      if (!known.count(key)) error(kv.first, "unknown key '" + key + "' in a calibration file");
    }
    if (readString(root["format"]).value_or("") != "facet-calibration 1")
      error(root["format"] ? root["format"] : root,
            "'format: facet-calibration 1' is missing or different (is this a calibration file?)");
    CalibrationData d;
    if (root["board"]) d.board = readString(root["board"]).value_or("");
    if (root["rms_px"]) d.rmsPx = nonNegative(root["rms_px"], "rms_px");
    if (root["mm_per_pixel"]) {
      d.mmPerPixel = nonNegative(root["mm_per_pixel"], "mm_per_pixel");
      if (d.mmPerPixel <= 0) error(root["mm_per_pixel"], "mm_per_pixel must be positive");
    }
    const bool lens = root["camera_matrix"] || root["distortion"] || root["image_size"];
    if (lens) {
      CameraModel camera;
      for (const char* key : {"camera_matrix", "distortion", "image_size"})
        if (!root[key])
          error(root, std::string("'") + key +
                          "' is missing: camera_matrix, distortion and image_size come together");
      if (root["camera_matrix"]) camera.cameraMatrix = cameraMatrix(root["camera_matrix"]);
      if (root["distortion"]) camera.distortion = distortion(root["distortion"]);
      if (root["image_size"]) {
        const auto v = numbers(root["image_size"], "image_size", 2);
        if (v.size() == 2) {
          if (v[0] < 1 || v[1] < 1 || v[0] > 1e5 || v[1] > 1e5 || v[0] != std::floor(v[0]) ||
              v[1] != std::floor(v[1]))
            error(root["image_size"],
                  "image_size must be two whole numbers of pixels, [width, height]");
          else
            camera.imageSize = {static_cast<int>(v[0]), static_cast<int>(v[1])};
        }
      }
      d.camera = camera;
    }
    if (root["plane"]) {
      if (!lens) error(root["plane"], "a plane needs camera_matrix, distortion and image_size");
      d.plane = plane(root["plane"]);
    } else if (!lens && !root["mm_per_pixel"]) {
      error(root,
            "a calibration needs a lens model (camera_matrix, distortion, image_size) or "
            "'mm_per_pixel'");
    }
    if (out_.errorCount() > before) return std::nullopt;
    return d;
  }

 private:
  void error(const YAML::Node& node, std::string message) {
    out_.error(locate(file_, node), std::move(message));
  }

  double nonNegative(const YAML::Node& node, const std::string& name) {
    const auto v = readNumber(node);
    if (!v || !std::isfinite(*v) || *v < 0) {
      error(node, name + " must be a number >= 0, not " + describe(node));
      return 0;
    }
    return *v;
  }

  // A flow or block sequence of `count` finite numbers (count 0: any length).
  std::vector<double> numbers(const YAML::Node& node, const std::string& name, std::size_t count) {
    std::vector<double> out;
    if (!node.IsSequence() || (count && node.size() != count)) {
      error(node, name + " must be a list of " + (count ? std::to_string(count) + " " : "") +
                      "numbers, not " + describe(node) +
                      (node.IsSequence() ? " of " + std::to_string(node.size()) : ""));
      return {};
    }
    for (const auto& item : node) {
      const auto v = readNumber(item);
      if (!v || !std::isfinite(*v)) {
        error(item, name + ": expected a number, not " + describe(item));
        return {};
      }
      out.push_back(*v);
    }
    return out;
  }

  std::optional<cv::Matx33d> matrix3(const YAML::Node& node, const std::string& name) {
    if (!node.IsSequence() || node.size() != 3) {
      error(node, name + " must be 3 rows of 3 numbers, not " + describe(node) +
                      (node.IsSequence() ? " of " + std::to_string(node.size()) + " rows" : ""));
      return std::nullopt;
    }
    cv::Matx33d m;
    for (int r = 0; r < 3; ++r) {
      const auto row =
          numbers(node[static_cast<std::size_t>(r)], name + " row " + std::to_string(r + 1), 3);
      if (row.size() != 3) return std::nullopt;
      for (int c = 0; c < 3; ++c) m(r, c) = row[static_cast<std::size_t>(c)];
    }
    return m;
  }

  cv::Matx33d cameraMatrix(const YAML::Node& node) {
    const auto m = matrix3(node, "camera_matrix");
    if (!m) return cv::Matx33d::eye();
    const auto& K = *m;
    if (K(0, 0) <= 0 || K(1, 1) <= 0 || K(1, 0) != 0 || K(2, 0) != 0 || K(2, 1) != 0 ||
        K(2, 2) != 1)
      error(node, "camera_matrix must be [[fx, s, cx], [0, fy, cy], [0, 0, 1]] with fx, fy > 0");
    return K;
  }

  cv::Mat distortion(const YAML::Node& node) {
    const auto v = numbers(node, "distortion", 0);
    if (!node.IsSequence()) return {};
    if (!validDistortionCount(v.size())) {
      if (!v.empty() || node.size() == 0)
        error(node, "distortion needs 4, 5, 8, 12 or 14 values (k1 k2 p1 p2 [k3 ...]), has " +
                        std::to_string(node.size()));
      return {};
    }
    return cv::Mat(v, true).reshape(1, 1);
  }

  PlanePose plane(const YAML::Node& node) {
    PlanePose p;
    if (!node.IsMap()) {
      error(node, "plane must be a map with rotation, translation_mm and offset_mm");
      return p;
    }
    for (const auto& kv : node) {
      const std::string key = kv.first.Scalar();
      if (key != "rotation" && key != "translation_mm" && key != "offset_mm")
        error(kv.first, "unknown key '" + key + "' in plane");
    }
    if (!node["rotation"] || !node["translation_mm"])
      error(node, "plane needs 'rotation' and 'translation_mm'");
    if (node["rotation"]) {
      if (const auto R = matrix3(node["rotation"], "plane rotation")) {
        const cv::Matx33d e = R->t() * *R - cv::Matx33d::eye();
        if (cv::norm(e) > 1e-6 || cv::determinant(*R) < 0)
          error(node["rotation"], "plane rotation is not a rotation matrix (orthonormal, det +1)");
        p.rotation = *R;
      }
    }
    if (node["translation_mm"]) {
      const auto t = numbers(node["translation_mm"], "translation_mm", 3);
      if (t.size() == 3) p.translationMm = {t[0], t[1], t[2]};
      if (t.size() == 3 && t[2] <= 0)
        error(node["translation_mm"],
              "translation_mm: the plate must lie in front of the camera (z > 0)");
    }
    if (node["offset_mm"]) {
      const auto v = readNumber(node["offset_mm"]);
      if (!v || !std::isfinite(*v))
        error(node["offset_mm"], "offset_mm must be a number, not " + describe(node["offset_mm"]));
      else
        p.offsetMm = *v;
    }
    return p;
  }

  const std::filesystem::path& file_;
  Diagnostics& out_;
};

// OpenCV reads a !!opencv-matrix by allocating rows x cols first: a mangled header (a byte for
// `cols`) asked for 17 GB (found by the calibration fuzzer). A calibration's matrices are small:
// their size is checked before OpenCV reads them. Nodes of another form are left to OpenCV.
bool smallOpenCvMatrix(const cv::FileNode& node) {
  if (!node.isMap()) return true;
  const cv::FileNode rows = node["rows"], cols = node["cols"];
  if (!rows.isInt() || !cols.isInt()) return false;
  const long long r = static_cast<int>(rows), c = static_cast<int>(cols);
  return r >= 0 && c >= 0 && r * c <= 64;
}

// OpenCV's YAML reader (4.6) never returns on some malformed files (found by the calibration
// fuzzer: a block map followed by a less indented line of flow values). yaml-cpp reads an OpenCV
// YAML file first, past OpenCV's own "%YAML:1.0" line, and the file goes to OpenCV only when it
// is a map whose camera_matrix and distortion_coefficients are small matrices (rows, cols and
// that many data values); otherwise it is reported, at its line where there is one.
bool wellFormedOpenCvYaml(const std::filesystem::path& file, Diagnostics& out) {
  std::ifstream in(file, std::ios::binary);
  std::string first;
  std::getline(in, first);
  if (first.rfind("%YAML", 0) != 0) return true;  // XML: OpenCV's own reader
  const std::string rest((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  YAML::Node root;
  try {
    root = YAML::Load(rest);
  } catch (const YAML::Exception& e) {
    out.error(
        {file, e.mark.is_null() ? 0 : e.mark.line + 2, e.mark.is_null() ? 0 : e.mark.column + 1},
        "not valid YAML: " + e.msg);
    return false;
  }
  if (!root.IsMap()) {
    out.error({file}, "an OpenCV calibration file is a map (camera_matrix, ...)");
    return false;
  }
  for (const char* key : {"camera_matrix", "distortion_coefficients"}) {
    bool small = false;
    try {
      const YAML::Node& map = root;
      const YAML::Node m = map[key];
      if (!m) {  // what the reading after would say
        out.error({file}, std::string(key) == "camera_matrix"
                              ? "needs a 3x3 'camera_matrix'"
                              : "needs 'distortion_coefficients' with 4, 5, 8, 12 or 14 values");
        return false;
      }
      if (m.IsMap()) {
        long long rows = -1, cols = -1;
        if (const auto r = readInteger(m["rows"])) rows = *r;
        if (const auto c = readInteger(m["cols"])) cols = *c;
        const YAML::Node data = m["data"];
        // Each side bounded first: the product of two large counts would overflow.
        small = rows >= 0 && cols >= 0 && rows <= 64 && cols <= 64 && rows * cols <= 64 && data &&
                data.IsSequence() && static_cast<long long>(data.size()) == rows * cols;
      }
    } catch (const YAML::Exception&) {
      small = false;
    }
    if (!small) {
      out.error({file}, std::string("'") + key +
                            "' is not a small matrix (integer rows and cols, at most 64 values, "
                            "that many data)");
      return false;
    }
  }
  return true;
}

// OpenCV FileStorage files as written before facet had its own format.
std::optional<CalibrationData> readOpenCvFile(const std::filesystem::path& file, Diagnostics& out) {
  if (!wellFormedOpenCvYaml(file, out)) return std::nullopt;
  CalibrationData d;
  CameraModel camera;
  cv::Mat K, D;
  try {
    cv::FileStorage fs(file.string(), cv::FileStorage::READ);
    if (!fs.isOpened()) {
      out.error({file}, "cannot be opened by OpenCV");
      return std::nullopt;
    }
    for (const char* key : {"camera_matrix", "distortion_coefficients"})
      if (!smallOpenCvMatrix(fs[key])) {
        out.error({file}, std::string("'") + key +
                              "' is not a small matrix (integer rows and cols, at most 64 values)");
        return std::nullopt;
      }
    fs["camera_matrix"] >> K;
    fs["distortion_coefficients"] >> D;
    if (!fs["mm_per_pixel"].empty()) d.mmPerPixel = static_cast<double>(fs["mm_per_pixel"]);
    if (!fs["image_width"].empty() && !fs["image_height"].empty())
      camera.imageSize = {static_cast<int>(fs["image_width"]),
                          static_cast<int>(fs["image_height"])};
  } catch (const cv::Exception& e) {
    out.error({file}, "not readable: " + e.msg);
    return std::nullopt;
  } catch (const std::exception& e) {
    // OpenCV's parser lets some standard exceptions through on malformed files (found by the
    // calibration fuzzer: a mangled !!opencv-matrix header).
    out.error({file}, std::string("not readable: ") + e.what());
    return std::nullopt;
  }
  bool ok = true;
  if (K.rows != 3 || K.cols != 3) {
    out.error({file}, "needs a 3x3 'camera_matrix'");
    ok = false;
  }
  if (!validDistortionCount(D.total())) {
    out.error({file}, "needs 'distortion_coefficients' with 4, 5, 8, 12 or 14 values (has " +
                          std::to_string(D.total()) + ")");
    ok = false;
  }
  if (!ok) return std::nullopt;
  K.convertTo(K, CV_64F);
  D = D.reshape(1, 1);
  D.convertTo(camera.distortion, CV_64F);
  camera.cameraMatrix = cv::Matx33d(K);
  d.camera = camera;
  return d;
}

std::string row(const double* v, int n) {
  std::ostringstream o;
  o << std::setprecision(17) << "[";
  for (int i = 0; i < n; ++i) o << (i ? ", " : "") << v[i];
  o << "]";
  return o.str();
}

}  // namespace

std::string CalibrationData::kind() const {
  if (camera && plane) return "lens model + plane";
  if (camera) return "lens model, scale only";
  return "scale only, no lens model";
}

std::optional<CalibrationData> readCalibrationFile(const std::filesystem::path& file,
                                                   Diagnostics& out) {
  std::ifstream in(file);
  std::string first;
  std::getline(in, first);
  if (first.rfind("%YAML:1.0", 0) == 0 || first.rfind("<?xml", 0) == 0)
    return readOpenCvFile(file, out);
  return CalibrationReader(file, out).read();
}

std::string calibrationFileText(const CalibrationData& d, const std::string& comment) {
  std::ostringstream o;
  std::istringstream lines(comment);
  for (std::string line; std::getline(lines, line);) o << "# " << line << "\n";
  o << "format: facet-calibration 1\n";
  if (!d.board.empty()) o << "board: " << d.board << "\n";
  o << std::setprecision(17);
  if (d.camera) {
    const auto& c = *d.camera;
    o << "image_size: [" << c.imageSize.width << ", " << c.imageSize.height << "]\n";
    o << "rms_px: " << d.rmsPx << "\n";
    o << "camera_matrix:\n";
    for (int r = 0; r < 3; ++r) o << "  - " << row(&c.cameraMatrix(r, 0), 3) << "\n";
    const cv::Mat dist = c.distortion.empty() ? cv::Mat::zeros(1, 5, CV_64F) : c.distortion;
    o << "distortion: " << row(dist.ptr<double>(), static_cast<int>(dist.total())) << "\n";
  }
  if (d.plane) {
    o << "plane:\n  rotation:\n";
    for (int r = 0; r < 3; ++r) o << "    - " << row(&d.plane->rotation(r, 0), 3) << "\n";
    o << "  translation_mm: " << row(d.plane->translationMm.val, 3) << "\n";
    o << "  offset_mm: " << d.plane->offsetMm << "\n";
  }
  if (d.mmPerPixel > 0) o << "mm_per_pixel: " << d.mmPerPixel << "\n";
  return o.str();
}

}  // namespace facet::config
