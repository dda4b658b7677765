// facet scan-match: aligns one 2D range scan (CSV) to a reference scan (CSV).
#include <chrono>
#include <cmath>
#include <fstream>
#include <iostream>
#include <numbers>
#include <sstream>

#include "algorithms/scan/scan_csv.hpp"
#include "algorithms/scan/scan_match.hpp"
#include "service/cli/command_line.hpp"

namespace facet::cli {
namespace {

struct ScanMatchOptions {
  std::string reference;
  std::string scan;
  std::string init;  // "x,y,theta_deg"
  std::string method = "idcp";
  bool json = false;
};

scan::Scan readCsvScan(const std::string& path) {
  std::ifstream in(path);
  if (!in) throw InputError(path + ": cannot open scan file");
  try {
    return scan::readScanCsv(in, path);
  } catch (const scan::ScanFormatError& e) {
    throw InputError(e.what());
  }
}

scan::ScanPose parseInit(const std::string& text) {
  scan::ScanPose pose;
  if (text.empty()) return pose;
  std::istringstream in(text);
  char c1 = 0, c2 = 0;
  double thetaDeg = 0.0;
  if (!(in >> pose.x >> c1 >> pose.y >> c2 >> thetaDeg) || c1 != ',' || c2 != ',' ||
      !(in >> std::ws).eof() || !std::isfinite(pose.x) || !std::isfinite(pose.y) ||
      !std::isfinite(thetaDeg))
    throw InputError("--init: expected x,y,theta_deg (metres, metres, degrees), got '" + text +
                     "'");
  pose.theta = thetaDeg * std::numbers::pi / 180.0;
  return pose;
}

scan::ScanMatchMethod parseMethod(const std::string& name) {
  using M = scan::ScanMatchMethod;
  for (const M m : {M::IcpPointToPoint, M::IcpPointToLine, M::Dcp, M::IdcpBoc})
    if (scan::toString(m) == name) return m;
  throw InputError("--method: expected icp, icp-line, dcp or idcp, got '" + name + "'");
}

void run(const ScanMatchOptions& options) {
  scan::ScanMatchParams params;
  params.method = parseMethod(options.method);
  const scan::ScanPose initial = parseInit(options.init);
  const scan::Scan reference = readCsvScan(options.reference);
  const scan::Scan scan = readCsvScan(options.scan);

  const auto t0 = std::chrono::steady_clock::now();
  const scan::ScanMatchResult r = scan::matchScans(reference, scan, initial, params);
  const double ms =
      std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
  if (r.status.cause == scan::MatchCause::EmptyScan)
    throw MeasurementFailure("empty_scan", "too few points to match: reference has " +
                                               std::to_string(reference.size()) + ", scan has " +
                                               std::to_string(scan.size()));
  if (r.status.cause == scan::MatchCause::TooFewCorrespondences)
    throw MeasurementFailure("too_few_correspondences",
                             "the scans do not overlap enough from the initial pose");
  const double thetaDeg = r.pose.theta * 180.0 / std::numbers::pi;
  if (options.json) {
    printJson({{"x", r.pose.x},
               {"y", r.pose.y},
               {"theta", thetaDeg},
               {"iterations", r.iterations},
               {"rms", r.rms},
               {"correspondences", r.correspondences},
               {"converged", r.status.ok()},
               {"cause", std::string(scan::toString(r.status.cause))},
               {"method", options.method},
               {"time_ms", ms}});
    return;
  }
  std::cout << "pose: x " << r.pose.x << " m, y " << r.pose.y << " m, theta " << thetaDeg
            << " deg\n"
            << "iterations " << r.iterations << ", rms " << r.rms << " m, correspondences "
            << r.correspondences << ", " << (r.status.ok() ? "converged" : "not converged") << " ("
            << scan::toString(r.status.cause) << "), " << ms << " ms\n";
}

}  // namespace

void addScanMatchCommand(CLI::App& app) {
  auto options = std::make_shared<ScanMatchOptions>();
  auto* cmd = app.add_subcommand(
      "scan-match",
      "Align a 2D range scan to a reference scan (CSV: x,y metres or angle_deg,range); prints the "
      "pose mapping the scan into the reference frame");
  cmd->add_option("--ref", options->reference, "Reference scan (CSV)")->required();
  cmd->add_option("--scan", options->scan, "Scan to align (CSV)")->required();
  cmd->add_option("--init", options->init, "Initial pose x,y,theta_deg (metres, degrees)");
  cmd->add_option("--method", options->method, "icp | icp-line | dcp | idcp (default idcp)");
  cmd->add_flag("--json", options->json, "Print one JSON object");
  cmd->callback([options] { run(*options); });
}

}  // namespace facet::cli
