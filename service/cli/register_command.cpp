// facet register: registers an image to a reference image (Harris / Harris-Affine points,
// log-polar windows, NCC, robust fit) and prints the transform reference -> image.
#include <chrono>
#include <iostream>

#include "algorithms/registration/register_images.hpp"
#include "service/cli/command_line.hpp"

namespace facet::cli {
namespace {

struct RegisterOptions {
  std::string ref;
  std::string image;
  std::string model = "homography";
  bool affine = false;
  bool noEscalation = false;
  int corners = RegistrationParams{}.corners.maxCorners;
  bool json = false;
  bool pairs = false;
};

void run(const RegisterOptions& o) {
  RegistrationParams p;
  if (!parseTransformModel(o.model, p.model))
    throw InputError("--model must be similarity, affine or homography (got \"" + o.model + "\")");
  p.affineRegions = o.affine;
  p.escalateToAffine = !o.noEscalation;
  p.corners.maxCorners = o.corners;
  const cv::Mat ref = readGreyImage(o.ref);
  const cv::Mat image = readGreyImage(o.image);

  const auto t0 = std::chrono::steady_clock::now();
  const RegistrationResult r = registerImages(ref, image, p);
  const double ms =
      std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
  if (!r.status.ok())
    throw MeasurementFailure(std::string(toString(r.status.cause)),
                             o.image + " against " + o.ref + ": " + r.status.message);

  const std::vector<cv::Vec4d> pairs = r.pairs();
  if (o.json) {
    nlohmann::json H = nlohmann::json::array();
    for (int k = 0; k < 9; ++k) H.push_back(r.H(k / 3, k % 3));
    nlohmann::json out{{"H", H},
                       {"matches", r.matches.size()},
                       {"inliers", r.inliers.size()},
                       {"global_inliers", r.globalInliers},
                       {"consensus_rank", r.consensusRank},
                       {"stage", r.stage},
                       {"escalated", r.escalated},
                       {"defocus_px", r.defocus},
                       {"refine_passes", r.refinePasses},
                       {"refine_last_move_px", r.refineLastMove},
                       {"overlap_uncertainty_px", r.overlapUncertainty},
                       {"time_ms", ms}};
    // Thousands of pairs (over 100 KB) only when asked for: the summary is what a line needs.
    if (o.pairs) {
      nlohmann::json jp = nlohmann::json::array();
      for (const auto& q : pairs) jp.push_back({q[0], q[1], q[2], q[3]});
      out["pairs"] = std::move(jp);
    }
    printJson(out);
  } else {
    std::cout << "H (reference -> image):\n";
    for (int i = 0; i < 3; ++i)
      std::cout << "  " << r.H(i, 0) << " " << r.H(i, 1) << " " << r.H(i, 2) << "\n";
    std::cout << r.matches.size() << " matches, " << r.inliers.size() << " inliers, " << ms
              << " ms, stage " << r.stage << (r.escalated ? " (after the plain Harris stage)" : "")
              << "\n";
    if (r.consensusRank > 0)
      std::cout << "the global fit's runner-up " << r.consensusRank << " was confirmed ("
                << r.globalInliers << " global inliers)\n";
    std::cout << "re-matched in " << r.refinePasses << " passes, the last moving H by "
              << r.refineLastMove << " px\n";
    std::cout << "the part of the reference the image sees is placed within "
              << r.overlapUncertainty << " px (1 sigma)\n";
    // A camera out of focus shows here first: the re-matching blurred one view to the other.
    if (r.defocus > 0)
      std::cout << "the image is more blurred than the reference (Gaussian sigma " << r.defocus
                << " px)\n";
    else if (r.defocus < 0)
      std::cout << "the reference is more blurred than the image (Gaussian sigma " << -r.defocus
                << " px)\n";
  }
}

}  // namespace

void addRegisterCommand(CLI::App& app) {
  auto* cmd = app.add_subcommand(
      "register",
      "Register an image to a reference: prints H mapping reference pixels to image pixels");
  auto o = std::make_shared<RegisterOptions>();
  cmd->add_option("--ref", o->ref, "Reference image")->required();
  cmd->add_option("--image", o->image, "Image to register to the reference")->required();
  cmd->add_option("--model", o->model, "Transform: similarity, affine or homography")
      ->capture_default_str();
  cmd->add_flag("--affine", o->affine,
                "Harris-Affine regions from the start (by default they are used only when plain "
                "Harris corners find no transform to stand on)");
  cmd->add_flag("--no-escalation", o->noEscalation,
                "Plain Harris corners only: never escalate to Harris-Affine regions");
  cmd->add_option("--corners", o->corners, "Corner budget per image")->capture_default_str();
  cmd->add_flag("--json", o->json, "Print one JSON object: H, matches, inliers, time_ms");
  cmd->add_flag("--pairs", o->pairs,
                "With --json, also the inlier pairs [x_ref, y_ref, x_image, y_image]");
  cmd->callback([o] { run(*o); });
}

}  // namespace facet::cli
