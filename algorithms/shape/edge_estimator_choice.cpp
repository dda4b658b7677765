#include "algorithms/shape/edge_estimator_choice.hpp"

#include <cmath>
#include <iterator>
#include <limits>
#include <numbers>
#include <stdexcept>
#include <vector>

#include <opencv2/core/utility.hpp>
#include <opencv2/imgproc.hpp>

#include "algorithms/shape/find_shape_model.hpp"

namespace facet {
namespace {

// Known poses of the turned copies: angles in degrees and shifts in pixels, small enough that
// the turned template still holds almost all of the part, uneven so that no copy samples the
// edges as the template does.
struct Turn {
  double degrees;
  double dx;
  double dy;
};
constexpr Turn kTurns[] = {{-5.5, 0.31, -0.17}, {-4.0, -0.12, 0.27}, {-2.5, 0.46, 0.38},
                           {-1.0, -0.23, 0.41}, {1.0, 0.44, 0.12},   {2.5, -0.41, -0.06},
                           {4.0, -0.37, -0.29}, {5.5, 0.08, -0.44}};
constexpr double kSearchHalfRange = 2.0 * std::numbers::pi / 180.0;  // around the known angle

// True when `errors` are lower than `than` on average, copy by copy. A copy that one of them did
// not find counts for the other. No margin favours either estimator: where the profile fit is
// the better (rendered blurred steps) it wins the trial by a factor of 3, while a margin for it
// (twice the copies' standard error, the earlier rule) kept it on parts cut from photographs
// where the zero crossing is the better: in bench_turned_photos (seeds 41-131) the 90% quantile
// of the pose error over the model's points was 0.091-0.138 px per seed with the margin,
// 0.065-0.118 px without; with --capture 0.088-0.131 and 0.077-0.098 px.
bool findsCopiesBetter(const std::vector<double>& errors, const std::vector<double>& than) {
  double gain = 0.0;
  int compared = 0;
  for (std::size_t i = 0; i < errors.size(); ++i) {
    if (std::isinf(errors[i]) && std::isinf(than[i])) continue;
    if (std::isinf(errors[i])) return false;
    if (std::isinf(than[i])) return true;
    gain += than[i] - errors[i];
    ++compared;
  }
  return compared > 0 && gain > 0.0;
}

}  // namespace

EdgeEstimatorChoice chooseEdgeEstimator(const cv::Mat& templateImage,
                                        const std::vector<const ShapeModel*>& candidates) {
  EdgeEstimatorChoice choice;
  if (candidates.empty()) return choice;
  // One turned copy serves every candidate: they differ only in their edge estimator.
  for (const ShapeModel* model : candidates)
    if (model->referencePoint != candidates.front()->referencePoint)
      throw std::invalid_argument("chooseEdgeEstimator: the candidates' reference points differ");
  // The copies lie on a canvas a quarter larger, so that turned corners of the part stay in view:
  // the image around a region where it has one (copyMakeBorder reads beyond a region of a larger
  // image), the template's border repeated beyond.
  const int margin = std::max(templateImage.cols, templateImage.rows) / 8 + 4;
  cv::Mat canvas;
  cv::copyMakeBorder(templateImage, canvas, margin, margin, margin, margin, cv::BORDER_REPLICATE);

  // Per candidate, per turned copy. Each copy is warped once for all candidates, and the copies
  // are tried in parallel (each search on one thread): with a large template (1126x973 pixels)
  // the trials were 1.4 s of the training's 1.6, a Lanczos warp 33 ms of each.
  constexpr int kCopies = static_cast<int>(std::size(kTurns));
  std::vector<std::vector<double>> errors(candidates.size(), std::vector<double>(kCopies));
  const cv::Point2d centre = candidates.front()->referencePoint + cv::Point2d(margin, margin);
  cv::parallel_for_(cv::Range(0, kCopies), [&](const cv::Range& range) {
    for (int i = range.start; i < range.end; ++i) {
      const Turn& turn = kTurns[i];
      cv::Mat warp = cv::getRotationMatrix2D(centre, turn.degrees, 1.0);
      warp.at<double>(0, 2) += turn.dx;
      warp.at<double>(1, 2) += turn.dy;
      cv::Mat copy;
      cv::warpAffine(canvas, copy, warp, canvas.size(), cv::INTER_LANCZOS4, cv::BORDER_REPLICATE);
      const double angle = turn.degrees * std::numbers::pi / 180.0;
      const Pose2D truth{centre.x + turn.dx, centre.y + turn.dy, angle, 1.0};

      FindParams find;
      find.minScore = 0.3;
      find.angleStart = angle - kSearchHalfRange;
      find.angleExtent = 2.0 * kSearchHalfRange;
      find.threads = 1;
      for (std::size_t c = 0; c < candidates.size(); ++c) {
        const std::vector<ShapeMatch> matches = findShapeModel(copy, *candidates[c], find);
        errors[c][static_cast<std::size_t>(i)] =
            matches.empty() ? std::numeric_limits<double>::infinity()
                            : candidates[c]->pointsDistance(matches.front().pose(), truth);
      }
    }
  });
  for (std::size_t c = 0; c < candidates.size(); ++c) {
    double sum = 0.0;
    for (const double v : errors[c]) sum += v * v;
    choice.trials.push_back({candidates[c]->edgeEstimator, std::sqrt(sum / kCopies)});
  }

  int profile = -1, zeroCrossing = -1;
  for (int i = 0; i < static_cast<int>(choice.trials.size()); ++i)
    (choice.trials[i].estimator == EdgeEstimator::ProfileFit ? profile : zeroCrossing) = i;
  if (profile < 0) {
    choice.chosen = EdgeEstimator::FacetZeroCrossing;
  } else if (zeroCrossing >= 0 && findsCopiesBetter(errors[zeroCrossing], errors[profile])) {
    choice.chosen = EdgeEstimator::FacetZeroCrossing;
  }
  return choice;
}

}  // namespace facet
