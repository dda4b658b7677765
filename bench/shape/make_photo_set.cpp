// make_photo_set: builds tests/data/photos/ (templates, scenes, reference poses) from the
// photographs that Debian's opencv-doc package installs, and draws each reference onto its scene
// for checking by eye. The reference poses come from methods independent of shape matching:
//   warp    the scene is the photograph turned and scaled by a known similarity (exact);
//   sift    a second photograph of the part; SIFT matches + RANSAC similarity fit, refined by a
//           dense alignment (ECC) where that converges (see denseRefinement);
//   circles round parts; cv::HoughCircles centres (angle not compared);
//   blobs   dark parts on a light table; centroid and principal axis of each blob (angle mod 180).
//
//   make_photo_set SOURCE_DIR OUT_DIR CHECK_DIR
//   (SOURCE_DIR = /usr/share/doc/opencv-doc/examples/data)
//
// Writes OUT_DIR/cases.txt: one line per case,
//   name template scene angle_period n  x y angle_deg scale  (n times)  method
// angle_period 360 = compare angles, 180 = modulo a half turn, 0 = do not compare.

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <numbers>
#include <optional>
#include <string>
#include <vector>

#include <opencv2/calib3d.hpp>
#include <opencv2/features2d.hpp>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <opencv2/video/tracking.hpp>

namespace {

struct Pose {
  double x, y, angleDeg, scale;
};

struct Case {
  std::string name;
  std::string method;
  std::string templateFile;  // in SOURCE_DIR
  cv::Rect roi;              // of the template image; empty = all
  std::string sceneFile;     // in SOURCE_DIR (warp: the same photograph)
  double angleDeg = 0.0;     // warp only
  double scale = 1.0;        // warp only
};

// Our convention: q = t + s R(a) p with R(a) = [[cos a, sin a], [-sin a, cos a]].
Pose poseFromSimilarity(const cv::Mat& m, cv::Point2d reference) {
  const double a = m.at<double>(0, 0), b = m.at<double>(0, 1);
  const cv::Point2d q(
      a * reference.x + b * reference.y + m.at<double>(0, 2),
      m.at<double>(1, 0) * reference.x + m.at<double>(1, 1) * reference.y + m.at<double>(1, 2));
  return {q.x, q.y, std::atan2(b, a) * 180.0 / std::numbers::pi, std::hypot(a, b)};
}

cv::Point2d centreOf(cv::Rect r) {
  return {r.x + (r.width - 1) / 2.0, r.y + (r.height - 1) / 2.0};
}

// The similarity from the template photograph to the scene (empty when none is found).
cv::Mat siftSimilarity(const cv::Mat& templ, cv::Rect roi, const cv::Mat& scene) {
  auto sift = cv::SIFT::create();
  std::vector<cv::KeyPoint> kt, ks;
  cv::Mat dt, ds;
  cv::Mat mask(templ.size(), CV_8U, cv::Scalar(0));
  mask(roi).setTo(255);
  sift->detectAndCompute(templ, mask, kt, dt);
  sift->detectAndCompute(scene, cv::noArray(), ks, ds);
  cv::BFMatcher matcher(cv::NORM_L2);
  std::vector<std::vector<cv::DMatch>> knn;
  matcher.knnMatch(dt, ds, knn, 2);
  std::vector<cv::Point2f> from, to;
  for (const auto& m : knn)
    if (m.size() == 2 && m[0].distance < 0.75f * m[1].distance) {
      from.push_back(kt[m[0].queryIdx].pt);
      to.push_back(ks[m[0].trainIdx].pt);
    }
  std::vector<uchar> inliers;
  const cv::Mat m = cv::estimateAffinePartial2D(from, to, inliers, cv::RANSAC, 2.0, 5000, 0.999);
  int n = 0;
  for (uchar i : inliers) n += i;
  std::printf("  sift: %zu ratio matches, %d inliers\n", from.size(), n);
  return m;
}

// The SIFT fit refined by ECC (cv::findTransformECC, every pixel of the template, OpenCV's
// default smoothing), as an affine map of the template region: a part that moved between two
// frames is not quite a similarity, and the affine map is the 2D model nearest its motion. The
// reference is where that map puts the template's centre, the angle of its rotation part and its
// mean scale. SIFT's keypoints alone left rubberwhale_letter 1.1 px and 2.6 degrees from where
// the whole template correlates best (0.979 at SIFT's pose, 0.997 at ECC's). Kept only where the
// alignment converges to a correlation of at least 0.99. Tried where the part is seen at the
// template's size (the two rubberwhale frames); box and leuven_gable, seen at another size from
// another viewpoint, keep SIFT's fit (ECC from there peaks at 0.78 and 0.92).
std::optional<Pose> denseRefinement(const cv::Mat& templ, cv::Rect roi, const cv::Mat& scene,
                                    const cv::Mat& similarity) {
  // The similarity maps the template photograph; the ECC warp maps the cut template.
  cv::Mat warp = similarity.clone();
  warp.col(2) += similarity.colRange(0, 2) * (cv::Mat_<double>(2, 1) << roi.x, roi.y);
  warp.convertTo(warp, CV_32F);
  double correlation = 0.0;
  try {
    correlation = cv::findTransformECC(
        templ, scene, warp, cv::MOTION_AFFINE,
        cv::TermCriteria(cv::TermCriteria::COUNT | cv::TermCriteria::EPS, 500, 1e-8), cv::noArray(),
        5);
  } catch (const cv::Exception&) {
    std::printf("  ecc: did not converge; SIFT's fit kept\n");
    return std::nullopt;
  }
  if (correlation < 0.99) {
    std::printf("  ecc: correlation %.4f below 0.99; SIFT's fit kept\n", correlation);
    return std::nullopt;
  }
  warp.convertTo(warp, CV_64F);
  const cv::Point2d c((templ.cols - 1) / 2.0, (templ.rows - 1) / 2.0);
  const double a = warp.at<double>(0, 0), b = warp.at<double>(0, 1);
  const double d = warp.at<double>(1, 0), e = warp.at<double>(1, 1);
  const Pose ref{
      a * c.x + b * c.y + warp.at<double>(0, 2), d * c.x + e * c.y + warp.at<double>(1, 2),
      std::atan2(b - d, a + e) * 180.0 / std::numbers::pi, std::sqrt(std::abs(a * e - b * d))};
  std::printf("  ecc: correlation %.4f\n", correlation);
  return ref;
}

std::vector<Pose> circleReference(const cv::Mat& scene, double radius) {
  std::vector<cv::Vec3f> circles;
  cv::Mat blurred;
  cv::GaussianBlur(scene, blurred, {5, 5}, 1.5);
  cv::HoughCircles(blurred, circles, cv::HOUGH_GRADIENT, 1.0, radius * 1.5, 100, 25,
                   static_cast<int>(0.8 * radius), static_cast<int>(1.2 * radius));
  std::vector<Pose> out;
  for (const auto& c : circles) {
    // Parts wholly inside the image count; those cut by its border are optional (scale 0): a
    // match there is neither found nor false.
    const bool whole = c[0] - c[2] >= 1 && c[1] - c[2] >= 1 && c[0] + c[2] <= scene.cols - 2 &&
                       c[1] + c[2] <= scene.rows - 2;
    out.push_back({c[0], c[1], 0.0, whole ? 1.0 : 0.0});
  }
  return out;
}

// Dark blobs larger than minArea: centroid and principal-axis angle (our convention).
std::vector<std::pair<cv::Point2d, double>> darkBlobs(const cv::Mat& grey, double minArea) {
  cv::Mat dark;
  cv::threshold(grey, dark, 0, 255, cv::THRESH_BINARY_INV | cv::THRESH_OTSU);
  std::vector<std::vector<cv::Point>> contours;
  cv::findContours(dark, contours, cv::RETR_EXTERNAL, cv::CHAIN_APPROX_NONE);
  std::vector<std::pair<cv::Point2d, double>> out;
  for (const auto& c : contours) {
    const cv::Moments m = cv::moments(c);
    if (m.m00 < minArea) continue;
    const cv::Rect b = cv::boundingRect(c);
    if (b.x <= 0 || b.y <= 0 || b.br().x >= grey.cols || b.br().y >= grey.rows) continue;
    // Axis angle on screen (y down): theta = 0.5 atan2(2 mu11, mu20 - mu02) turns clockwise.
    const double theta = 0.5 * std::atan2(2 * m.mu11, m.mu20 - m.mu02);
    out.push_back({{m.m10 / m.m00, m.m01 / m.m00}, -theta * 180.0 / std::numbers::pi});
  }
  return out;
}

void drawPose(cv::Mat& canvas, const Pose& p, cv::Size templ) {
  const double a = p.angleDeg * std::numbers::pi / 180.0;
  const double c = std::cos(a) * p.scale, s = std::sin(a) * p.scale;
  const double hw = (templ.width - 1) / 2.0, hh = (templ.height - 1) / 2.0;
  std::vector<cv::Point> corners;
  for (auto [u, v] : {std::pair{-hw, -hh}, {hw, -hh}, {hw, hh}, {-hw, hh}})
    corners.emplace_back(cvRound(p.x + c * u + s * v), cvRound(p.y - s * u + c * v));
  cv::polylines(canvas, corners, true, {0, 0, 255}, 2);
  cv::line(canvas, {cvRound(p.x), cvRound(p.y)},
           {cvRound(p.x + c * hw * 0.6), cvRound(p.y - s * hw * 0.6)}, {0, 255, 0}, 2);
}

}  // namespace

int main(int argc, char** argv) {
  if (argc != 4) {
    std::fprintf(stderr, "usage: make_photo_set SOURCE_DIR OUT_DIR CHECK_DIR\n");
    return 2;
  }
  const std::string src = std::string(argv[1]) + "/", out = std::string(argv[2]) + "/",
                    check = std::string(argv[3]) + "/";
  const std::vector<Case> cases = {
      {"box", "sift", "box.png", {}, "box_in_scene.png"},
      {"board_qfp100", "warp", "board.jpg", {332, 292, 176, 152}, "board.jpg", 33.0, 1.0},
      {"board_qfp44", "warp", "board.jpg", {300, 122, 68, 70}, "board.jpg", -117.0, 0.99},
      {"board_crystal", "warp", "board.jpg", {372, 196, 82, 40}, "board.jpg", 71.0, 1.0},
      {"board_dip", "warp", "board.jpg", {36, 52, 152, 60}, "board.jpg", 171.5, 1.01},
      {"blox_block", "warp", "blox.jpg", {124, 140, 52, 70}, "blox.jpg", 145.0, 1.0},
      {"stuff_lighter", "warp", "stuff.jpg", {298, 298, 66, 160}, "stuff.jpg", -52.0, 1.01},
      {"smarties", "circles", "smarties.png", {4, 200, 60, 58}, "smarties.png"},
      {"propellers", "blobs", "pca_test1.jpg", {}, "pca_test1.jpg"},
      {"rubberwhale_letter", "sift", "rubberwhale1.png", {150, 222, 165, 112}, "rubberwhale2.png"},
      {"rubberwhale_toy", "sift", "rubberwhale1.png", {220, 86, 116, 108}, "rubberwhale2.png"},
      {"leuven_gable", "sift", "leuvenA.jpg", {262, 160, 156, 190}, "leuvenB.jpg"},
  };
  // The board photograph itself, for bench_shape_real's large-image row.
  std::filesystem::copy_file(src + "board.jpg", out + "board_source.jpg",
                             std::filesystem::copy_options::overwrite_existing);
  std::ofstream manifest(out + "cases.txt");
  manifest << "# name template scene angle_period count (x y angle_deg scale)... method\n";
  for (Case c : cases) {
    std::printf("%s (%s)\n", c.name.c_str(), c.method.c_str());
    const cv::Mat templSource = cv::imread(src + c.templateFile, cv::IMREAD_GRAYSCALE);
    cv::Mat scene = cv::imread(src + c.sceneFile, cv::IMREAD_GRAYSCALE);
    if (templSource.empty() || scene.empty()) {
      std::fprintf(stderr, "cannot read %s or %s\n", c.templateFile.c_str(), c.sceneFile.c_str());
      return 1;
    }
    std::vector<Pose> refs;
    int period = 360;
    if (c.method == "blobs") {
      // The template: the upright part, its region centred on its own centroid so that the
      // reference point is the centroid and the half-turn ambiguity leaves positions alone.
      const auto blobs = darkBlobs(scene, 5000);
      std::size_t upright = 0;
      for (std::size_t i = 0; i < blobs.size(); ++i)
        if (std::abs(std::abs(blobs[i].second) - 90) <
            std::abs(std::abs(blobs[upright].second) - 90))
          upright = i;
      const cv::Point2d g = blobs[upright].first;
      c.roi = cv::Rect(cvRound(g.x) - 37, cvRound(g.y) - 186, 75, 373);
      const double templAngle = blobs[upright].second;
      const cv::Point2d roiCentre = centreOf(c.roi);
      for (const auto& [centre, angle] : blobs)
        refs.push_back(
            {centre.x + roiCentre.x - g.x, centre.y + roiCentre.y - g.y, angle - templAngle, 1.0});
      period = 180;
    }
    if (c.roi.empty()) c.roi = cv::Rect(0, 0, templSource.cols, templSource.rows);
    cv::Mat templ = templSource(c.roi).clone();
    if (c.method == "warp") {
      const cv::Point2f centre((scene.cols - 1) / 2.0f, (scene.rows - 1) / 2.0f);
      const cv::Mat m = cv::getRotationMatrix2D(centre, c.angleDeg, c.scale);
      cv::Mat warped;
      // A constant border (the photograph's mean grey): a reflected one would add mirrored parts.
      cv::warpAffine(scene, warped, m, scene.size(), cv::INTER_CUBIC, cv::BORDER_CONSTANT,
                     cv::mean(scene));
      scene = warped;
      refs.push_back(poseFromSimilarity(m, centreOf(c.roi)));
    } else if (c.method == "sift") {
      const cv::Mat m = siftSimilarity(templSource, c.roi, scene);
      if (m.empty()) return 1;
      // A part seen at another size: the template is scaled to it, as a user trains at the
      // working distance. Its centre, mapped back into the photograph (cv::resize maps x' to
      // (x' + 0.5) / k - 0.5), is the point whose image the reference gives.
      const double k = std::hypot(m.at<double>(0, 0), m.at<double>(0, 1));
      cv::Point2d centre = centreOf(c.roi);
      if (std::abs(k - 1.0) > 0.05) {
        cv::resize(templ, templ, {}, k, k, cv::INTER_AREA);
        centre = cv::Point2d(c.roi.x + (templ.cols / 2.0) / k - 0.5,
                             c.roi.y + (templ.rows / 2.0) / k - 0.5);
        std::printf("  template scaled by %.4f to %dx%d\n", k, templ.cols, templ.rows);
      }
      Pose ref = poseFromSimilarity(m, centre);
      if (std::abs(k - 1.0) > 0.05) {
        ref.scale /= k;
      } else {
        cv::Mat grey;
        templ.convertTo(grey, CV_32F);
        cv::Mat sceneGrey;
        scene.convertTo(sceneGrey, CV_32F);
        if (const std::optional<Pose> dense = denseRefinement(grey, c.roi, sceneGrey, m))
          ref = *dense;
      }
      refs.push_back(ref);
    } else if (c.method == "circles") {
      refs = circleReference(scene, c.roi.width / 2.0 - 3);
      period = 0;
    }
    const std::string templName = c.name + "_template.png";
    cv::imwrite(out + templName, templ);
    // Photographs are kept as published (bytes unchanged); warped ones are written as PNG.
    const std::string sceneName = c.method == "warp" ? c.name + "_scene.png" : c.sceneFile;
    if (c.method == "warp")
      cv::imwrite(out + sceneName, scene);
    else
      std::filesystem::copy_file(src + c.sceneFile, out + sceneName,
                                 std::filesystem::copy_options::overwrite_existing);
    manifest << c.name << ' ' << templName << ' ' << sceneName << ' ' << period << ' '
             << refs.size();
    cv::Mat canvas;
    cv::cvtColor(scene, canvas, cv::COLOR_GRAY2BGR);
    for (const Pose& p : refs) {
      char buf[128];
      std::snprintf(buf, sizeof buf, "  %.3f %.3f %.3f %.5f", p.x, p.y, p.angleDeg, p.scale);
      manifest << buf;
      std::printf("  ref%s\n", buf);
      drawPose(canvas, p, templ.size());
    }
    manifest << ' ' << c.method << '\n';
    cv::imwrite(check + c.name + ".png", canvas);
  }
  return 0;
}
