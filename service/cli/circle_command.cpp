// facet circle: measures one circle in an image around a given centre and nominal radius.
#include <chrono>
#include <cmath>
#include <iomanip>
#include <iostream>
#include <optional>
#include <sstream>

#include "algorithms/circle/circle_measure.hpp"
#include "service/cli/command_line.hpp"
#include "service/cli/world_circle.hpp"

namespace facet::cli {
namespace {

struct CircleOptions {
  std::string image;
  std::string centre;
  double radius = 0;
  double width = CircleMeasureParams{}.width;
  std::string polarity = "any";
  double minCoverage = CircleMeasureParams{}.minCoverageDeg;
  std::string calibration;  // calibration file: adds the circle in the measuring plane, mm
  bool json = false;
};

cv::Point2d parseCentre(const std::string& text) {
  std::istringstream in(text);
  double x = 0, y = 0;
  char comma = 0;
  if (!(in >> x >> comma >> y) || comma != ',' || !(in >> std::ws).eof())
    throw InputError("--centre/--center must be x,y in pixels (got \"" + text + "\")");
  return {x, y};
}

// The recipe's words (a hole is dark inside), and the edge's direction going outwards.
CirclePolarity parsePolarity(const std::string& text) {
  if (text == "dark_inside" || text == "dark_to_light") return CirclePolarity::DarkToLight;
  if (text == "light_inside" || text == "light_to_dark") return CirclePolarity::LightToDark;
  if (text == "any") return CirclePolarity::Any;
  throw InputError("--polarity must be dark_inside, light_inside or any (got \"" + text + "\")");
}

void run(const CircleOptions& o) {
  CircleMeasureParams p;
  p.centre = parseCentre(o.centre);
  p.radius = o.radius;
  p.width = o.width;
  p.polarity = parsePolarity(o.polarity);
  p.minCoverageDeg = o.minCoverage;
  const cv::Mat image = readGreyImage(o.image);
  std::optional<MeasuringPlane> plane;
  if (!o.calibration.empty()) plane.emplace(o.calibration, image.size());

  const auto t0 = std::chrono::steady_clock::now();
  const CircleMeasurement m = measureCircle(image, p);
  // With a plane, a rim the image refused as a circle (an ellipse on a steep view) is measured
  // and judged in the plane; the time includes it.
  std::string inPlane;
  const nlohmann::json world = plane ? worldCircle(*plane, image, m, p, inPlane) : nlohmann::json();
  const double ms =
      std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
  if (m.status.cause == CircleFailure::BadInput)
    throw InputError(o.image + ": " + m.status.message);
  if (!m.status.ok() && world.is_null())
    throw MeasurementFailure(
        std::string(toString(m.status.cause)),
        o.image + ": " + m.status.message + (inPlane.empty() ? "" : "; " + inPlane));
  if (!m.status.ok()) {
    // Refused as a circle in the image, measured in the plane: the image fields say so.
    const cv::Point2d at =
        plane->mapping()->toImage({world["x_mm"].get<double>(), world["y_mm"].get<double>()});
    if (o.json) {
      printJson({{"x", at.x},
                 {"y", at.y},
                 {"image_refusal", std::string(toString(m.status.cause)) + ": " + m.status.message},
                 {"time_ms", ms},
                 {"world", world}});
    } else {
      std::cout << std::setprecision(6) << "the image refused the rim as a circle ("
                << m.status.message << "); measured in the plane: centre ("
                << world["x_mm"].get<double>() << ", " << world["y_mm"].get<double>()
                << ") mm, diameter " << world["diameter_mm"].get<double>() << " mm, image point ("
                << at.x << ", " << at.y << ") px, " << ms << " ms\n";
    }
    return;
  }
  if (o.json) {
    nlohmann::json out{{"x", m.centre.x},
                       {"y", m.centre.y},
                       {"radius", m.radius},
                       {"diameter", m.diameter},
                       {"roundness", m.roundness},
                       {"rms", m.rms},
                       {"inliers", m.inliers},
                       {"coverage_deg", m.coverageDeg},
                       // Whether centre and radius come from the grey-value fit (and its blur) or,
                       // when that fit did not converge, from the edge points alone: an engineer
                       // judging a result needs to know which.
                       {"grey_refined", m.greyRefined},
                       {"blur", m.blur},
                       // The share of the pixels near the rim the sensor clipped (0 or its
                       // largest value): fitted as clipped; a sign to lower the exposure.
                       {"clipped_share", m.clippedShare},
                       {"elliptic", m.elliptic},
                       {"time_ms", ms}};
    // An elliptic rim (a tilted view): its axes, in pixels, and the major one's direction in
    // degrees counter-clockwise; centre and radius above are the ellipse's centre and the radius
    // of the circle of its area.
    if (m.elliptic)
      out["ellipse"] = {
          {"major", m.majorDiameter}, {"minor", m.minorDiameter}, {"angle", m.majorAxisDeg}};
    if (!world.is_null()) out["world"] = world;
    printJson(out);
  } else {
    std::cout << std::setprecision(6) << "centre (" << m.centre.x << ", " << m.centre.y
              << ") px, radius " << m.radius << " px, diameter " << m.diameter << " px\nroundness "
              << m.roundness << " px, rms " << m.rms << " px, " << m.inliers << " inliers covering "
              << m.coverageDeg << " deg, " << ms << " ms\n"
              << (m.greyRefined ? "refined on the grey values, blur "
                                : "from the edge points only (grey-value fit did not converge)");
    if (m.greyRefined) std::cout << m.blur << " px";
    std::cout << "\n";
    if (m.clippedShare > 0.0)
      std::cout << 100.0 * m.clippedShare
                << "% of the pixels near the rim are at the sensor's limit"
                << (m.greyRefined
                        ? ": fitted as clipped (lower the exposure for the best precision)\n"
                        : ": its edge points lie off there (lower the exposure)\n");
    if (m.elliptic)
      std::cout << "the rim is an ellipse: axes " << m.majorDiameter << " x " << m.minorDiameter
                << " px, the major one at " << m.majorAxisDeg
                << " deg; centre and radius are the ellipse's centre and the radius of its area\n";
    if (!world.is_null())
      std::cout << "in the plane: centre (" << world["x_mm"].get<double>() << ", "
                << world["y_mm"].get<double>() << ") mm, diameter "
                << world["diameter_mm"].get<double>() << " mm ("
                << world["calibration"].get<std::string>() << ")\n";
  }
}

}  // namespace

void addCircleCommand(CLI::App& app) {
  auto* cmd = app.add_subcommand("circle",
                                 "Measure a circle (hole, bore, round part) to subpixel "
                                 "accuracy in an annulus around a given position");
  auto o = std::make_shared<CircleOptions>();
  cmd->add_option("--image", o->image, "8/16-bit image file")->required();
  cmd->add_option("--centre,--center", o->centre, "expected centre x,y in pixels")->required();
  cmd->add_option("--radius", o->radius, "nominal radius in pixels")->required();
  cmd->add_option("--width", o->width, "half-width of the search annulus in pixels (default 5)");
  cmd->add_option("--polarity", o->polarity,
                  "dark_inside (a hole), light_inside or any (default); as in recipes "
                  "(dark_to_light and light_to_dark are accepted too)");
  cmd->add_option("--min-coverage", o->minCoverage,
                  "minimum angular coverage of the rim in degrees (default 180)");
  cmd->add_option("--calibration", o->calibration,
                  "calibration file (facet calibrate): adds the circle in the measuring plane, mm");
  cmd->add_flag("--json", o->json, "Print one JSON object");
  cmd->callback([o] { run(*o); });
}

}  // namespace facet::cli
