#pragma once
// A recipe in memory: what the line inspects for one part type, as validated by loadRecipe()
// (recipe_loader.hpp). Recipes are immutable once loaded; the daemon holds them through
// shared_ptr<const Recipe> (recipe_library.hpp) and switches between them only between parts.
//
// Units: image positions (centre, marks, regions) are pixels; lengths of the part (diameters,
// search widths, distances) are millimetres and become pixels through the station's calibration;
// angles are degrees. A check's `unit` says how its measured value is expressed.
//
// What the steps give and how later steps use it (the contract for the recipe engine):
// - Every step with a pose (align, fiducials, shape) maps positions written in its frame into
//   the live image. The frame of an align step is its reference image's pixels: registration
//   gives the similarity reference -> live; a shape match gives the model pose, applied to
//   p - r where r is the model's reference point in reference pixels (the centre of `region`,
//   or of the whole template). The frame of a fiducials step is that of its nominal `marks`
//   (its relative_to step's frame, or the live image's pixels without one); its pose is the
//   similarity that takes the nominal marks onto the found ones.
// - A step with `relative_to` writes its positions (circle centre, search regions) in that
//   step's frame, and its angle range is relative to that step's angle. Without `relative_to`
//   they are pixels of the live image.
// - Position checks (x, y, position) are offsets from nominal in millimetres along the axes of
//   the relative_to step's frame (of the live image without one).
// - For `distance`: the point of a step is the image of its reference point (align: the centre
//   of its region, r for method shape; shape: r of the best match), the circle's centre, or the
//   centroid of the found marks (fiducials); the line of a pose step runs through its point
//   along its x axis.
// - scan_align reports the pose that takes the live scan onto the reference scan's frame; its x
//   and y checks are millimetres, angle degrees.

#include <filesystem>
#include <optional>
#include <string>
#include <string_view>
#include <variant>
#include <vector>

#include <opencv2/core/types.hpp>

#include "config/diagnostic.hpp"
#include "config/field_spec.hpp"
#include "plc/register_map.hpp"

namespace facet::config {

inline constexpr int kRecipeSchemaVersion = 1;

enum class Unit { Millimetre, Degree, Pixel, None };

// Where a checked value goes on the PLC. `output` is the PLC module's own description (name
// "<step id>.<check name>", holding register counted like the station's register map, encoding,
// word order), ready to be added to the station's RegisterMap::results.
struct PlcOutput {
  plc::ResultOutput output;
  SourceLocation where;  // of the `register:` value

  // Holding registers the value occupies (1 or 2).
  [[nodiscard]] int words() const { return plc::registerCount(output.type); }
};

// One checked value: passes when nominal - tolMinus <= measured <= nominal + tolPlus.
struct Check {
  std::string name;  // "diameter", "x", "angle", ...
  Quantity quantity = Quantity::Length;
  double nominal = 0.0;
  double tolMinus = 0.0;  // >= 0
  double tolPlus = 0.0;   // >= 0
  Unit unit = Unit::Millimetre;
  std::optional<PlcOutput> plc;
  SourceLocation where;

  [[nodiscard]] double lower() const { return nominal - tolMinus; }
  [[nodiscard]] double upper() const { return nominal + tolPlus; }
  [[nodiscard]] bool passes(double measured) const {
    return measured >= lower() && measured <= upper();
  }
};

// Grey values of a round feature compared to its surroundings.
enum class CirclePolarity { DarkInside, LightInside, Any };

struct AngleRange {
  double low = -180.0;  // degrees
  double high = 180.0;
};

// `align`: finds the part and gives the pose that later steps' positions follow.
struct AlignStep {
  enum class Method { Registration, Shape };
  Method method = Method::Registration;
  std::filesystem::path reference;             // reference image (registration) or template (shape)
  std::optional<cv::Rect2d> region;            // part of the reference used; empty = all of it
  std::optional<std::filesystem::path> model;  // trained shape model (method shape)
  std::optional<cv::Rect2d> searchRegion;      // where to search in the live image; empty = all
  double minScore = 0.7;                       // 0..1
  AngleRange angleRange;
};

// `fiducials`: finds round marks near their nominal positions; reports shift and rotation.
struct FiducialsStep {
  std::optional<std::string> relativeTo;  // id of an earlier pose step
  std::vector<cv::Point2d> marks;         // nominal mark centres, pixels; at least 2
  double markDiameter = 1.0;              // mm
  double searchRadius = 1.0;              // mm around each nominal centre
  CirclePolarity polarity = CirclePolarity::Any;
};

// `shape`: finds a trained shape model and checks count and pose.
struct ShapeStep {
  std::optional<std::string> relativeTo;
  std::filesystem::path templateImage;  // the image the model is trained from
  std::optional<cv::Rect2d> region;     // part of the template; empty = all of it
  std::filesystem::path model;          // trained model file, written by `facet recipe train`
  std::optional<cv::Rect2d> searchRegion;
  double minScore = 0.7;
  int numMatches = 1;
  AngleRange angleRange;
  double maxOverlap = 0.5;
};

// `circle`: measures a circle in an annulus around its nominal position.
struct CircleStep {
  std::optional<std::string> relativeTo;
  cv::Point2d centre;          // pixels of the relative_to step's reference image
  double nominalDiameter = 0;  // mm
  double searchWidth = 0;      // mm, width of the annulus searched around the nominal circle
  CirclePolarity polarity = CirclePolarity::Any;
};

// `distance`: a distance or angle between the results of two earlier steps.
struct DistanceStep {
  enum class Measure { CentreToCentre, PointToLine, Angle };
  Measure measure = Measure::CentreToCentre;
  std::string from;  // step id: a point (or a line for Angle)
  std::string to;    // step id: a point (CentreToCentre) or a line (PointToLine, Angle)
};

// `scan_align`: registers a live 2D range scan to a reference scan; reports the pose offset.
struct ScanAlignStep {
  enum class Method { Icp, Dcp, Idcp };
  std::filesystem::path reference;  // CSV scan, rows "x,y" in metres
  Method method = Method::Dcp;
  int maxIterations = 50;
  double maxDistance = 5.0;  // mm, correspondences farther apart are ignored
};

enum class StepKind { Align, Fiducials, Shape, Circle, Distance, ScanAlign };

using StepParams =
    std::variant<AlignStep, FiducialsStep, ShapeStep, CircleStep, DistanceStep, ScanAlignStep>;

struct Step {
  std::string id;    // unique within the recipe
  std::string name;  // for people; defaults to the id
  StepKind kind = StepKind::Align;
  StepParams params;
  std::vector<Check> checks;  // in file order
  SourceLocation where;

  [[nodiscard]] const Check* check(std::string_view checkName) const;
  template <class T>
  [[nodiscard]] const T& as() const {
    return std::get<T>(params);
  }
};

struct Recipe {
  int schemaVersion = kRecipeSchemaVersion;
  int id = 0;  // what the PLC selects, 1..65535
  std::string name;
  std::string description;
  std::string version;               // free text from the file (may be empty)
  std::string contentHash;           // FNV-1a 64 of the recipe file's bytes, 16 hex digits
  SourceLocation idWhere;            // of the `id:` value, for messages about duplicate ids
  std::filesystem::path file;        // the recipe file
  std::filesystem::path baseFolder;  // folder its relative paths start from
  std::vector<Step> steps;           // in execution order
  // Every other file the recipe reads (images, models, scans), absolute; a change to one of them
  // changes the recipe.
  std::vector<std::filesystem::path> dependencies;

  [[nodiscard]] const Step* step(std::string_view stepId) const;
  // Every PLC output of the recipe's checks, in file order.
  [[nodiscard]] std::vector<std::pair<const Check*, const Step*>> plcOutputs() const;
};

std::string_view toString(StepKind kind);
std::string_view toString(Unit unit);
std::string_view toString(CirclePolarity polarity);

}  // namespace facet::config
