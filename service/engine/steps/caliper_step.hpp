#pragma once
// `caliper`: edges or edge pairs along a rectangle or an arc placed on the part (an edge's
// position, a slot's or a bar's width, the count and pitch of repeated edges such as pins or a
// comb, or of teeth and slots around a hub).

#include <optional>
#include <string>

#include "algorithms/measure/caliper.hpp"
#include "service/engine/table_step.hpp"

namespace facet::service {

struct CaliperStepParams : config::StepParams {
  enum class Measure { Edges, Pairs };
  std::optional<std::string> relativeTo;
  // A rectangle (length, angle) or an arc (radius, start_angle, extent) around `centre`.
  cv::Point2d centre;            // pixels of the relative_to step's reference image
  std::optional<double> length;  // rectangle: pixels, along the measuring axis
  double width = 0;              // pixels, across the axis (radially on an arc), averaged over
  double angle = 0;              // rectangle: degrees, relative to the relative_to step's rotation
  std::optional<double> radius;  // arc: pixels
  std::optional<double> startAngle;  // arc: degrees, counter-clockwise on screen, relative too
  std::optional<double> extent;      // arc: degrees; negative runs clockwise
  Measure measure = Measure::Edges;
  EdgePolarity polarity = EdgePolarity::Any;
  EdgeSelect select = EdgeSelect::All;
  double minAmplitude = 20.0;  // grey levels (8-bit scale)
};

class CaliperStep : public TableStep<CaliperStepParams> {
 public:
  CaliperStep();
  [[nodiscard]] StepResult run(const config::Step& step, StepContext& part) const override;

 private:
  void crossCheck(const CaliperStepParams& params, config::StepReading& in) const override;
};

}  // namespace facet::service
