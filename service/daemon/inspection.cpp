#include "service/daemon/inspection.hpp"

#include <chrono>
#include <cmath>
#include <map>

#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "algorithms/circle/circle_measure.hpp"
#include "algorithms/circle/disc_locator.hpp"
#include "algorithms/geometry/pose2d.hpp"
#include "algorithms/geometry/similarity_fit.hpp"
#include "algorithms/image/grey_image.hpp"
#include "algorithms/registration/register_images.hpp"
#include "algorithms/scan/scan_file.hpp"
#include "algorithms/scan/scan_match.hpp"
#include "algorithms/shape/find_shape_model.hpp"
#include "algorithms/shape/shape_model_file.hpp"

namespace facet::service {

using config::Step;

struct RecipeInspection::Resources {
  std::map<std::string, cv::Mat> references;      // by step id: grey reference image (align)
  std::map<std::string, ShapeModel> models;       // by step id (align by shape, shape)
  std::map<std::string, cv::Point2d> modelHomes;  // by step id: the model's reference point in
                                                  // its template image (the nominal position)
  std::map<std::string, scan::Scan> scans;        // by step id (scan_align)
};

namespace {

using Clock = std::chrono::steady_clock;

// What a step leaves for the checks and for later steps.
struct StepResult {
  bool ok = true;
  std::string cause;                        // why !ok
  std::optional<cv::Matx33d> refToImage;    // pose steps: reference pixels -> live pixels
  std::optional<cv::Rect2d> referenceView;  // pose steps: the reference's extent, its pixels
  std::optional<cv::Point2d> point;         // a position in the live image
  std::optional<double> angleDeg;           // an orientation in the live image
  std::map<std::string, double> values;     // by check name; lengths in px (or mm, see below)
  bool lengthsInMm = false;                 // scan_align measures metric scans, not pixels
};

StepResult failed(std::string cause) {
  StepResult r;
  r.ok = false;
  r.cause = std::move(cause);
  return r;
}

cv::Mat readGrey(const std::filesystem::path& file) {
  cv::Mat image = cv::imread(file.string(), cv::IMREAD_UNCHANGED);
  if (image.empty()) throw InspectionSetupError(file.string() + ": cannot read image");
  return toGrey(image);
}

cv::Matx33d translation(cv::Point2d t) {
  return {1, 0, t.x, 0, 1, t.y, 0, 0, 1};
}

// The homography of a pose (q = t + s R(a) p) applied to p = r - home.
cv::Matx33d poseMap(const Pose2D& pose, cv::Point2d home) {
  const double c = std::cos(pose.angle) * pose.scale, s = std::sin(pose.angle) * pose.scale;
  const cv::Matx33d m{c, s, pose.x, -s, c, pose.y, 0, 0, 1};
  return m * translation(-home);
}

// Rotation (degrees, counter-clockwise on screen) of a near-similarity map at point p.
double rotationDeg(const cv::Matx33d& H, cv::Point2d p) {
  const cv::Point2d q0 = mapPoint(H, p), q1 = mapPoint(H, p + cv::Point2d(10, 0));
  return degrees(std::atan2(-(q1.y - q0.y), q1.x - q0.x));
}

cv::Rect clampRect(const std::optional<cv::Rect2d>& r, cv::Size size) {
  if (!r) return {0, 0, size.width, size.height};
  const cv::Rect rect(cvRound(r->x), cvRound(r->y), cvRound(r->width), cvRound(r->height));
  return rect & cv::Rect(0, 0, size.width, size.height);
}

FindParams findParams(double minScore, int numMatches, double maxOverlap,
                      const config::AngleRange& range) {
  FindParams p;
  p.minScore = minScore;
  p.numMatches = numMatches;
  p.maxOverlap = maxOverlap;
  p.angleStart = radians(range.low);
  p.angleExtent = radians(range.high - range.low);
  p.subpixel = SubpixelMode::LeastSquares;
  return p;
}

// The map from reference pixels to the live image of the step a step is relative to.
cv::Matx33d relativeMap(const std::optional<std::string>& relativeTo,
                        const std::map<std::string, StepResult>& done) {
  if (!relativeTo) return cv::Matx33d::eye();
  return *done.at(*relativeTo).refToImage;
}

class StepRunner {
 public:
  StepRunner(const config::Recipe& recipe, const RecipeInspection::Resources& res,
             double mmPerPixel, const InspectionInput& input, Overlay& overlay)
      : recipe_(recipe),
        res_(res),
        mmPerPixel_(mmPerPixel),
        input_(input),
        grey_(toGrey(input.image)),
        overlay_(overlay) {}

  StepResult run(const Step& step, const std::map<std::string, StepResult>& done) {
    switch (step.kind) {
      case config::StepKind::Align:
        return align(step);
      case config::StepKind::Fiducials:
        return fiducials(step, done);
      case config::StepKind::Shape:
        return shape(step, done);
      case config::StepKind::Circle:
        return circle(step, done);
      case config::StepKind::Distance:
        return distance(step, done);
      case config::StepKind::ScanAlign:
        return scanAlign(step);
    }
    return failed("unknown step kind");
  }

 private:
  StepResult align(const Step& step) {
    const auto& a = step.as<config::AlignStep>();
    const cv::Rect search = clampRect(a.searchRegion, grey_.size());
    if (search.empty()) return failed("search region outside the image");
    const cv::Mat live = grey_(search);
    overlay_.polygon(corners(search), true, true);
    StepResult r;
    if (a.method == config::AlignStep::Method::Shape) {
      const auto& model = res_.models.at(step.id);
      const auto matches =
          findShapeModel(live, model, findParams(a.minScore, 1, 0.5, a.angleRange));
      if (matches.empty())
        return failed("part not found (no match above min score " + std::to_string(a.minScore) +
                      ")");
      const cv::Point2d home = res_.modelHomes.at(step.id);
      r.refToImage = translation(cv::Point2d(search.tl())) * poseMap(matches[0].pose(), home);
      r.values["score"] = matches[0].score;
      r.referenceView = cv::Rect2d(home - model.referencePoint, cv::Size2d(model.templateSize));
      drawContour(matches[0].contour, search.tl(), true);
      return withPoseValues(std::move(r), home);
    }
    const cv::Mat& ref = res_.references.at(step.id);
    const cv::Rect region = clampRect(a.region, ref.size());
    // The whole reference view is registered: log-polar windows need room around each corner,
    // which a tight part region does not give. The region sets the nominal point and outline.
    RegistrationParams params;
    params.model = TransformModel::Similarity;
    const RegistrationResult reg = registerImages(ref, live, params);
    if (!reg.ok) return failed("alignment failed: " + reg.failureCause);
    r.refToImage = translation(cv::Point2d(search.tl())) * reg.H;
    r.referenceView = cv::Rect2d(region);
    r.values["score"] =
        reg.matches.empty() ? 0.0 : static_cast<double>(reg.inliers.size()) / reg.matches.size();
    std::vector<cv::Point2d> outline;
    for (const auto& c : corners(region)) outline.push_back(mapPoint(*r.refToImage, c));
    overlay_.polygon(outline, r.values["score"] >= a.minScore);
    if (r.values["score"] < a.minScore)
      return failed("alignment score " + std::to_string(r.values["score"]) + " below " +
                    std::to_string(a.minScore));
    const cv::Point2d home(region.x + (region.width - 1) / 2.0,
                           region.y + (region.height - 1) / 2.0);
    return withPoseValues(std::move(r), home);
  }

  // x, y: offset of the reference point `home` from its nominal place; angle: rotation.
  static StepResult withPoseValues(StepResult r, cv::Point2d home) {
    const cv::Point2d found = mapPoint(*r.refToImage, home);
    r.values["x"] = found.x - home.x;
    r.values["y"] = found.y - home.y;
    r.angleDeg = rotationDeg(*r.refToImage, home);
    r.values["angle"] = *r.angleDeg;
    r.point = found;
    return r;
  }

  StepResult fiducials(const Step& step, const std::map<std::string, StepResult>& done) {
    const auto& f = step.as<config::FiducialsStep>();
    const cv::Matx33d H = relativeMap(f.relativeTo, done);
    std::vector<cv::Point2d> nominal, found;
    for (const auto& mark : f.marks) {
      const cv::Point2d expected = mapPoint(H, mark);
      const double radius = f.markDiameter / 2.0 / mmPerPixel_;
      const double searchRadius = f.searchRadius / mmPerPixel_;
      overlay_.circle(expected, searchRadius + radius, true, true);
      const std::string where =
          "mark at (" + std::to_string(mark.x) + ", " + std::to_string(mark.y) + ")";
      // Coarse location first: the search radius is usually larger than the mark.
      const auto coarse = locateDisc(grey_, {.expected = expected,
                                             .radius = radius,
                                             .searchRadius = searchRadius,
                                             .polarity = circlePolarity(f.polarity)});
      if (!coarse) return failed(where + " not found within the search radius");
      CircleMeasureParams p;
      p.centre = coarse->centre;
      p.radius = radius;
      p.width = std::max(2.0, 0.35 * radius);
      p.polarity = circlePolarity(f.polarity);
      const CircleMeasurement m = measureCircle(grey_, p);
      if (!m.ok()) return failed(where + " not measured: " + circleFailureCause(m.failures));
      overlay_.circle(m.centre, m.radius, true);
      nominal.push_back(expected);
      found.push_back(m.centre);
    }
    const auto similarity = fitSimilarity(nominal, found);
    if (!similarity) return failed("the nominal fiducial positions coincide");
    const cv::Matx33d S = similarity->H;
    StepResult r;
    r.refToImage = S * H;
    cv::Point2d cn, cf;
    for (std::size_t i = 0; i < found.size(); ++i) cn += nominal[i], cf += found[i];
    cn *= 1.0 / nominal.size();
    cf *= 1.0 / found.size();
    r.values["x"] = cf.x - cn.x;
    r.values["y"] = cf.y - cn.y;
    r.angleDeg = degrees(std::atan2(-S(1, 0), S(0, 0)));
    r.values["angle"] = *r.angleDeg;
    r.values["spacing"] = cv::norm(found[1] - found[0]);
    r.point = cf;
    return r;
  }

  StepResult shape(const Step& step, const std::map<std::string, StepResult>& done) {
    const auto& s = step.as<config::ShapeStep>();
    cv::Rect search = clampRect(s.searchRegion, grey_.size());
    config::AngleRange angles = s.angleRange;
    if (s.relativeTo) {
      // Relative to an earlier pose: search only where that step's reference view lies in the
      // live image, with the angle range turned by that step's rotation.
      const StepResult& base = done.at(*s.relativeTo);
      if (base.referenceView) {
        std::vector<cv::Point2f> mapped;
        for (const auto& c : corners(cv::Rect(*base.referenceView)))
          mapped.emplace_back(mapPoint(*base.refToImage, c));
        const int margin = 8;
        search &=
            cv::boundingRect(mapped) + cv::Size(2 * margin, 2 * margin) - cv::Point(margin, margin);
      }
      if (base.angleDeg) angles = {angles.low + *base.angleDeg, angles.high + *base.angleDeg};
    }
    if (search.empty()) return failed("search region outside the image");
    overlay_.polygon(corners(search), true, true);
    const auto& model = res_.models.at(step.id);
    const auto matches = findShapeModel(grey_(search), model,
                                        findParams(s.minScore, s.numMatches, s.maxOverlap, angles));
    StepResult r;
    r.values["count"] = static_cast<double>(matches.size());
    for (const auto& m : matches) drawContour(m.contour, search.tl(), true);
    if (matches.empty()) {
      // Nothing found: the count is still a valid measurement (it may be checked against 0).
      if (step.check("count") != nullptr && step.checks.size() == 1) return r;
      return failed("no match above min score " + std::to_string(s.minScore));
    }
    cv::Point2d home = res_.modelHomes.at(step.id);
    // Relative to an earlier pose, the nominal position moves with the part.
    const cv::Point2d nominal = mapPoint(relativeMap(s.relativeTo, done), home);
    const ShapeMatch& best = matches[0];
    const cv::Point2d at(best.x + search.x, best.y + search.y);
    r.values["x"] = at.x - nominal.x;
    r.values["y"] = at.y - nominal.y;
    r.angleDeg = degrees(best.angle);
    r.values["angle"] = *r.angleDeg;
    r.values["score"] = best.score;
    r.refToImage = translation(cv::Point2d(search.tl())) * poseMap(best.pose(), home);
    r.referenceView = cv::Rect2d(home - model.referencePoint, cv::Size2d(model.templateSize));
    r.point = at;
    overlay_.cross(at, 8, true);
    return r;
  }

  StepResult circle(const Step& step, const std::map<std::string, StepResult>& done) {
    const auto& c = step.as<config::CircleStep>();
    const cv::Point2d expected = mapPoint(relativeMap(c.relativeTo, done), c.centre);
    CircleMeasureParams p;
    p.centre = expected;
    p.radius = c.nominalDiameter / 2.0 / mmPerPixel_;
    p.width = c.searchWidth / mmPerPixel_;
    p.polarity = circlePolarity(c.polarity);
    const CircleMeasurement m = measureCircle(grey_, p);
    overlay_.circle(expected, std::max(1.0, p.radius - p.width), true, true);
    overlay_.circle(expected, p.radius + p.width, true, true);
    if (!m.ok()) return failed("circle not measured: " + circleFailureCause(m.failures));
    StepResult r;
    r.values["diameter"] = m.diameter;
    r.values["x"] = m.centre.x - expected.x;
    r.values["y"] = m.centre.y - expected.y;
    r.values["position"] = cv::norm(m.centre - expected);
    r.values["roundness"] = m.roundness;
    r.point = m.centre;
    overlay_.circle(m.centre, m.radius, true);
    overlay_.cross(m.centre, 4, true);
    return r;
  }

  StepResult distance(const Step& step, const std::map<std::string, StepResult>& done) {
    const auto& d = step.as<config::DistanceStep>();
    const StepResult& from = done.at(d.from);
    const StepResult& to = done.at(d.to);
    StepResult r;
    switch (d.measure) {
      case config::DistanceStep::Measure::CentreToCentre:
        if (!from.point || !to.point) return failed("a step gives no position");
        r.values["distance"] = cv::norm(*from.point - *to.point);
        overlay_.polyline({*from.point, *to.point}, true);
        break;
      case config::DistanceStep::Measure::PointToLine: {
        if (!from.point || !to.point || !to.angleDeg) return failed("a step gives no line");
        const double a = radians(*to.angleDeg);
        const cv::Point2d dir(std::cos(a), -std::sin(a));
        const cv::Point2d v = *from.point - *to.point;
        r.values["distance"] = std::abs(v.x * dir.y - v.y * dir.x);
        break;
      }
      case config::DistanceStep::Measure::Angle:
        if (!from.angleDeg || !to.angleDeg) return failed("a step gives no orientation");
        r.values["angle"] = degrees(wrapAngle(radians(*to.angleDeg - *from.angleDeg)));
        break;
    }
    return r;
  }

  StepResult scanAlign(const Step& step) {
    const auto& s = step.as<config::ScanAlignStep>();
    if (!input_.scan) return failed("no live range scan for this frame");
    scan::ScanMatchParams p;
    p.method = s.method == config::ScanAlignStep::Method::Icp
                   ? scan::ScanMatchMethod::IcpPointToLine
               : s.method == config::ScanAlignStep::Method::Dcp ? scan::ScanMatchMethod::Dcp
                                                                : scan::ScanMatchMethod::IdcpBoc;
    p.maxIterations = s.maxIterations;
    p.initialGate = s.maxDistance / 1000.0;
    const auto result = scan::matchScans(res_.scans.at(step.id), *input_.scan, {}, p);
    if (!result.converged)
      return failed("scan registration did not converge: " + std::string(toString(result.cause)));
    StepResult r;
    r.lengthsInMm = true;
    r.values["x"] = result.pose.x * 1000.0;
    r.values["y"] = result.pose.y * 1000.0;
    r.values["angle"] = degrees(result.pose.theta);
    return r;
  }

  static facet::CirclePolarity circlePolarity(config::CirclePolarity p) {
    switch (p) {
      case config::CirclePolarity::DarkInside:
        return facet::CirclePolarity::DarkToLight;
      case config::CirclePolarity::LightInside:
        return facet::CirclePolarity::LightToDark;
      case config::CirclePolarity::Any:
        return facet::CirclePolarity::Any;
    }
    return facet::CirclePolarity::Any;
  }

  static std::vector<cv::Point2d> corners(const cv::Rect& r) {
    return {{r.x - 0.5, r.y - 0.5},
            {r.x + r.width - 0.5, r.y - 0.5},
            {r.x + r.width - 0.5, r.y + r.height - 0.5},
            {r.x - 0.5, r.y + r.height - 0.5}};
  }

  void drawContour(const std::vector<cv::Point2d>& contour, cv::Point offset, bool pass) {
    std::vector<cv::Point2d> pts;
    pts.reserve(contour.size());
    for (const auto& p : contour) pts.emplace_back(p.x + offset.x, p.y + offset.y);
    // Contours are point sets, not ordered polylines: drawn as dots.
    for (const auto& p : pts) overlay_.polyline({p}, pass);
  }

  const config::Recipe& recipe_;
  const RecipeInspection::Resources& res_;
  double mmPerPixel_;
  const InspectionInput& input_;
  cv::Mat grey_;
  Overlay& overlay_;
};

// The steps a step needs results from.
std::vector<std::string> dependencies(const Step& step) {
  std::vector<std::string> deps;
  std::visit(
      [&](const auto& p) {
        using P = std::decay_t<decltype(p)>;
        if constexpr (std::is_same_v<P, config::DistanceStep>) {
          deps = {p.from, p.to};
        } else if constexpr (requires { p.relativeTo; }) {
          if (p.relativeTo) deps.push_back(*p.relativeTo);
        }
      },
      step.params);
  return deps;
}

double toCheckUnit(double value, const config::Check& check, bool lengthsInMm, double mmPerPixel) {
  if (check.quantity != config::Quantity::Length) return value;
  if (lengthsInMm) return check.unit == config::Unit::Pixel ? value / mmPerPixel : value;
  return check.unit == config::Unit::Millimetre ? value * mmPerPixel : value;
}

std::string unitName(const config::Check& check) {
  switch (check.quantity) {
    case config::Quantity::Count:
      return "count";
    case config::Quantity::Score:
      return "score";
    default:
      return std::string(config::toString(check.unit));
  }
}

}  // namespace

RecipeInspection::RecipeInspection(std::shared_ptr<const config::Recipe> recipe, double mmPerPixel)
    : recipe_(std::move(recipe)), mmPerPixel_(mmPerPixel) {
  if (!recipe_) throw InspectionSetupError("no recipe");
  if (!(mmPerPixel_ > 0)) throw InspectionSetupError("calibration: mm per pixel must be > 0");
  auto res = std::make_shared<Resources>();
  auto loadModel = [&](const Step& step, const std::filesystem::path& model,
                       const std::optional<cv::Rect2d>& region) {
    try {
      ShapeModel m = loadShapeModel(model);
      const cv::Rect r =
          region ? cv::Rect(cvRound(region->x), cvRound(region->y), 0, 0) : cv::Rect();
      res->modelHomes[step.id] = m.referencePoint + cv::Point2d(r.x, r.y);
      res->models[step.id] = std::move(m);
    } catch (const std::exception& e) {
      throw InspectionSetupError(recipe_->file.string() + ": step '" + step.id + "': " + e.what() +
                                 " (train it with: facet recipe train " + recipe_->file.string() +
                                 ")");
    }
  };
  for (const Step& step : recipe_->steps) {
    if (step.kind == config::StepKind::Align) {
      const auto& a = step.as<config::AlignStep>();
      if (a.method == config::AlignStep::Method::Shape) {
        if (!a.model)
          throw InspectionSetupError(recipe_->file.string() + ": step '" + step.id +
                                     "' has no model");
        loadModel(step, *a.model, a.region);
      } else {
        res->references[step.id] = readGrey(a.reference);
      }
    } else if (step.kind == config::StepKind::Shape) {
      const auto& s = step.as<config::ShapeStep>();
      loadModel(step, s.model, s.region);
    } else if (step.kind == config::StepKind::ScanAlign) {
      const auto& s = step.as<config::ScanAlignStep>();
      try {
        res->scans[step.id] = scan::readScanCsvFile(s.reference.string());
      } catch (const std::exception& e) {
        throw InspectionSetupError(s.reference.string() + ": " + e.what());
      }
    }
  }
  resources_ = std::move(res);
}

InspectionOutcome RecipeInspection::inspect(const InspectionInput& input) const {
  InspectionOutcome out;
  const auto start = Clock::now();
  try {
    const bool needsImage =
        std::any_of(recipe_->steps.begin(), recipe_->steps.end(),
                    [](const Step& s) { return s.kind != config::StepKind::ScanAlign; });
    if (needsImage && input.image.empty()) throw std::invalid_argument("empty image");
    StepRunner runner(*recipe_, *resources_, mmPerPixel_, input, out.overlay);
    std::map<std::string, StepResult> done;
    bool allPass = true;
    for (const Step& step : recipe_->steps) {
      const auto t0 = Clock::now();
      StepResult result;
      std::string blockedBy;
      for (const auto& dep : dependencies(step))
        if (!done.at(dep).ok) blockedBy = dep;
      if (!blockedBy.empty())
        result = failed("depends on failed step '" + blockedBy + "'");
      else
        result = runner.run(step, done);
      out.timings.push_back(
          {step.id, std::chrono::duration<double, std::milli>(Clock::now() - t0).count()});
      if (!result.ok) {
        allPass = false;
        out.failedChecks.push_back(step.id + ": " + result.cause);
      }
      const std::size_t firstOfStep = out.measurements.size();
      bool stepPass = result.ok;
      // Every checked value is reported, failed steps included (as NaN), so that a row in the
      // results store always has the recipe's full set of values.
      for (const config::Check& check : step.checks) {
        Measurement m;
        m.name = step.id + "." + check.name;
        m.unit = unitName(check);
        m.nominal = check.nominal;
        m.tolMinus = check.tolMinus;
        m.tolPlus = check.tolPlus;
        m.checked = true;
        const auto it = result.values.find(check.name);
        if (result.ok && it != result.values.end()) {
          m.value = toCheckUnit(it->second, check, result.lengthsInMm, mmPerPixel_);
          m.pass = check.passes(m.value);
        } else {
          m.value = std::nan("");
          m.pass = false;
        }
        if (!m.pass) {
          allPass = false;
          stepPass = false;
          if (result.ok) out.failedChecks.push_back(m.name);
        }
        out.measurements.push_back(std::move(m));
      }
      if (result.point) {
        std::string text = step.id;
        for (std::size_t i = firstOfStep; i < out.measurements.size(); ++i)
          if (const auto& m = out.measurements[i]; std::isfinite(m.value)) {
            char buf[64];
            std::snprintf(buf, sizeof buf, " %s=%.3f", m.name.substr(step.id.size() + 1).c_str(),
                          m.value);
            text += buf;
          }
        out.overlay.label(*result.point + cv::Point2d(8, -8), text, stepPass);
      }
      done.emplace(step.id, std::move(result));
    }
    out.verdict = allPass ? Verdict::Pass : Verdict::Fail;
  } catch (const std::exception& e) {
    out.verdict = Verdict::Error;
    out.error = std::string("inspection fault: ") + e.what();
  }
  out.totalMs = std::chrono::duration<double, std::milli>(Clock::now() - start).count();
  return out;
}

void recordOutcome(PartResult& part, const InspectionOutcome& outcome) {
  part.verdict = outcome.verdict;
  part.measurements = outcome.measurements;
  part.failedChecks = outcome.failedChecks;
  part.error = outcome.error;
  part.timings = outcome.timings;
  part.inspectionMs = outcome.totalMs;
}

}  // namespace facet::service
