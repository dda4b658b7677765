#include "service/cli/calibration_report.hpp"

#include <cmath>
#include <fstream>
#include <sstream>

#include "algorithms/calibration/field_coverage.hpp"
#include "service/cli/command_line.hpp"

namespace facet::cli {
namespace {

std::string escape(const std::string& s) {
  std::string out;
  for (char c : s) {
    if (c == '<')
      out += "&lt;";
    else if (c == '>')
      out += "&gt;";
    else if (c == '&')
      out += "&amp;";
    else if (c == '"')
      out += "&quot;";
    else
      out += c;
  }
  return out;
}

}  // namespace

void writeCalibrationReport(const std::string& file, const BoardSpec& board, cv::Size size,
                            const CameraCalibration& c, const config::CalibrationData& data) {
  // Residual arrows are drawn this many times longer than they are, so that 0.01 px shows.
  double largest = 1e-9;
  for (const auto& v : c.views)
    for (const auto& r : v.residuals) largest = std::max(largest, cv::norm(r));
  const double gain = 40.0 / largest;
  std::vector<std::vector<cv::Point2d>> outlines;
  for (const auto& v : c.views)
    if (v.used) outlines.push_back(patternOutline(v.points, v.ids, board.cols, board.rows));

  std::ostringstream h;
  h << "<!doctype html><html><head><meta charset=\"utf-8\"><title>facet calibration</title>"
    << "<style>body{font-family:sans-serif;margin:2em}table{border-collapse:collapse}"
    << "td,th{border:1px solid #ccc;padding:2px 8px;text-align:left}svg{border:1px solid #888}"
    << "</style></head><body><h1>Camera calibration</h1>";
  h << "<p>Board " << escape(board.text()) << ", image " << size.width << "x" << size.height
    << ", RMS reprojection error <b>" << c.rmsPx << " px</b>, field covered <b>"
    << std::lround(100 * c.coverage) << "%</b>";
  if (!c.warning.empty()) h << " &mdash; warning: " << escape(c.warning);
  h << "</p><p>Calibration: " << escape(data.kind()) << ", distortion terms "
    << escape(c.distortionModel);
  if (data.plane) h << ", " << data.mmPerPixel << " mm per pixel at the image centre";
  h << "</p>";
  h << "<h2>Residuals over the field</h2><p>Each arrow: detected minus reprojected point, drawn "
    << gain << "x longer (largest " << largest << " px). Shaded: covered by some view.</p>";
  h << "<svg viewBox=\"0 0 " << size.width << " " << size.height << "\" width=\"800\">";
  for (const auto& o : outlines) {
    h << "<polygon fill=\"#dde8ff\" fill-opacity=\"0.35\" stroke=\"none\" points=\"";
    for (const auto& p : o) h << p.x << "," << p.y << " ";
    h << "\"/>";
  }
  for (const auto& v : c.views)
    for (std::size_t i = 0; v.used && i < v.points.size(); ++i) {
      const auto& p = v.points[i];
      const auto q = p + gain * v.residuals[i];
      h << "<line x1=\"" << p.x << "\" y1=\"" << p.y << "\" x2=\"" << q.x << "\" y2=\"" << q.y
        << "\" stroke=\"#c00\" stroke-width=\"2\"/>";
    }
  h << "</svg><h2>Views</h2><table><tr><th>file</th><th>used</th><th>RMS px</th><th>why not, "
       "or a reservation</th></tr>";
  for (const auto& v : c.views)
    h << "<tr><td>" << escape(v.name) << "</td><td>" << (v.used ? "yes" : "no") << "</td><td>"
      << (v.used ? std::to_string(v.rmsPx) : "") << "</td><td>"
      << escape(v.used ? v.note : v.status.message) << "</td></tr>";
  h << "</table></body></html>\n";
  std::ofstream out(file);
  out << h.str();
  if (!out) throw InputError(file + ": cannot write the report");
}

}  // namespace facet::cli
