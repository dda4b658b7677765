#pragma once
// What one step leaves for its checks and for the steps after it.

#include <map>
#include <optional>
#include <string>

#include <opencv2/core.hpp>

namespace facet::service {

struct StepResult {
  bool ok = true;
  std::string cause;  // why !ok, for people ("circle not measured: ...")
  std::string note;   // a reservation about a result that stands ("measured inside the image only")
  std::optional<cv::Matx33d> refToImage;    // pose steps: reference pixels -> live pixels
  std::optional<cv::Rect2d> referenceView;  // pose steps: the reference's extent, its pixels
  std::optional<cv::Point2d> point;         // a position in the live image
  std::optional<double> angleDeg;           // an orientation in the live image (a line's too)
  std::map<std::string, double> values;     // by check name; lengths in px (or mm, see below)
  bool lengthsInMm = false;                 // scan_align measures metric scans, not pixels

  // Adds a reservation to the note ("; " between two).
  void addNote(const std::string& reservation) {
    note = note.empty() ? reservation : note + "; " + reservation;
  }

  static StepResult failed(std::string cause) {
    StepResult r;
    r.ok = false;
    r.cause = std::move(cause);
    return r;
  }
};

}  // namespace facet::service
