#include "service/engine/steps/scan_align_step.hpp"

#include "algorithms/geometry/pose2d.hpp"
#include "algorithms/scan/scan_file.hpp"
#include "algorithms/scan/scan_format_error.hpp"
#include "algorithms/scan/scan_match.hpp"
#include "config/recipe_format.hpp"

namespace facet::service {
namespace {

using config::Quantity;
using Method = ScanAlignParams::Method;

struct ReferenceScan : config::StepResources {
  scan::Scan scan;
};

}  // namespace

ScanAlignStep::ScanAlignStep() : TableStep({}) {
  fields_.path("reference", &ScanAlignParams::reference,
               "Reference scan (CSV rows \"x,y\" in metres), relative to the recipe.", true);
  fields_.choice("method", &ScanAlignParams::method,
                 {{"icp", Method::Icp}, {"dcp", Method::Dcp}, {"idcp", Method::Idcp}},
                 "icp, dcp (dual closest point) or idcp (clustered).");
  fields_.integer("max_iterations", &ScanAlignParams::maxIterations, "Iterations at most.",
                  {.minimum = 1.0, .maximum = 1000.0});
  fields_.number("max_distance", &ScanAlignParams::maxDistance,
                 "Correspondences farther apart are ignored, mm.",
                 {.minimum = 0.0, .exclusiveMinimum = true});
  checks_ = {"scan_align checks",
             "",
             {config::checkField("x", Quantity::Length, "Offset of the scan along x."),
              config::checkField("y", Quantity::Length, "Offset of the scan along y."),
              config::checkField("angle", Quantity::Angle, "Rotation of the scan, degrees.")}};
  describe("scan_align", "Registers a live 2D range scan to a reference scan.");
}

std::shared_ptr<const config::StepResources> ScanAlignStep::prepare(const config::Step& step,
                                                                    config::StepReading& in) const {
  if (!in["reference"]) return nullptr;  // reported by the validator
  auto reference = std::make_shared<ReferenceScan>();
  try {
    reference->scan = scan::readScanCsvFile(step.as<ScanAlignParams>().reference.string());
  } catch (const std::exception& e) {
    in.error(in["reference"], "reference scan '" + in["reference"].Scalar() + "': " + e.what());
    return nullptr;
  }
  if (reference->scan.size() < 3) {
    in.error(in["reference"], "reference scan '" + in["reference"].Scalar() + "' has " +
                                  std::to_string(reference->scan.size()) +
                                  " points; at least 3 are needed");
    return nullptr;
  }
  return reference;
}

StepResult ScanAlignStep::run(const config::Step& step, StepContext& part) const {
  const auto& s = step.as<ScanAlignParams>();
  if (!part.scan) return StepResult::failed("no live range scan for this frame");
  scan::ScanMatchParams p;
  p.method = s.method == Method::Icp   ? scan::ScanMatchMethod::IcpPointToLine
             : s.method == Method::Dcp ? scan::ScanMatchMethod::Dcp
                                       : scan::ScanMatchMethod::IdcpBoc;
  p.maxIterations = s.maxIterations;
  p.initialGate = s.maxDistance / 1000.0;
  const auto result = scan::matchScans(step.resourcesAs<ReferenceScan>().scan, *part.scan, {}, p);
  if (!result.status.ok())
    return StepResult::failed("scan registration did not converge: " +
                              std::string(toString(result.status.cause)));
  StepResult r;
  r.lengthsInMm = true;
  r.values["x"] = result.pose.x * 1000.0;
  r.values["y"] = result.pose.y * 1000.0;
  r.values["angle"] = degrees(result.pose.theta);
  return r;
}

}  // namespace facet::service
