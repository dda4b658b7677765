#pragma once
// The golden-set gate (`facet validate`): a folder of recorded parts whose sidecars say what a
// recipe must find, checked before a changed recipe goes to a line.
//
// Per part, from its sidecar (<image>.json, or sidecar.json's "images" / "defaults"):
//   "expected_verdict": "pass" | "fail"                          (required)
//   "expected_values": {"<step>.<value>": {"value": 12.0, "tolerance": 0.02}, ...}  (optional)
// A part matches when its verdict is the expected one and every expected value was measured
// within its tolerance.

#include <map>
#include <string>
#include <vector>

#include "camera/sidecar_metadata.hpp"
#include "service/engine/part_result.hpp"

namespace facet::service {

struct ExpectedValue {
  double value = 0;
  double tolerance = 0;
};

struct GoldenMismatch {
  std::string file;
  std::string serial;
  std::string check;     // "verdict" or the value's name
  std::string expected;  // "pass", "12.000 +- 0.020"
  std::string got;       // "fail (bore.diameter)", "12.031"
};

// The mismatches of one inspected part against its sidecar entries (empty when it matches).
std::vector<GoldenMismatch> compareWithGolden(const PartResult& part,
                                              const SidecarMetadata::Entries& sidecar);

}  // namespace facet::service
