// facetd on a line of real peers: Aravis' fake GigE Vision camera (tests/support/
// fake_gige_camera, serving the recorded bracket_shape images in order) or the replay camera,
// and a pymodbus PLC (tests/plc/pymodbus_plc.py) that selects the recipe, raises each trigger,
// decodes the result registers and acknowledges. Every verdict is checked against the demo
// images' sidecars, every result register against the stored measurement, every database row
// against the part it belongs to.
#include <gtest/gtest.h>

#include <cmath>
#include <csignal>
#include <filesystem>
#include <sstream>
#include <string>

#include "tests/daemon/child_process.hpp"
#include "tests/daemon/line_run.hpp"
#include "tests/daemon/plc_line.hpp"
#include "tests/plc/pymodbus_peer.hpp"

namespace facet::daemon_test {
namespace {

using namespace std::chrono_literals;
const std::string kDemo = std::string(FACET_SOURCE_DIR) + "/recipes/demo/bracket_shape";
// The PLC selects it; facetd starts with the lowest id (1), so the switch is tested.
constexpr int kRecipe = 2;  // bracket_shape.recipe.yaml

// The result registers the PLC decoded equal what the store holds for the same part.
void expectRegistersMatch(const nlohmann::json& result, const StoredPart& part) {
  const std::string where = "part " + std::to_string(part.partId);
  EXPECT_EQ(result.at("pass").get<bool>(), part.verdict == "pass") << where;
  EXPECT_EQ(result.at("error").get<bool>(), part.verdict == "error") << where;
  EXPECT_EQ(result.at("error_code").get<int>() != 0, part.verdict == "error") << where;
  const auto& values = result.at("values");
  if (part.verdict == "error") {
    // Nothing measured: the outputs read "not measured" (float NaN, integers 0), never the
    // previous part's values.
    EXPECT_TRUE(values.at("bore_to_edge.distance").is_null()) << where;
    EXPECT_EQ(values.at("label.count").get<double>(), 0.0) << where;
    EXPECT_EQ(values.at("label_angle.angle").get<double>(), 0.0) << where;
    return;
  }
  const auto& m = part.measurements;
  ASSERT_TRUE(m.count("label.count") && m.count("bore_to_edge.distance") &&
              m.count("label_angle.angle"))
      << where << " lacks a measurement";
  EXPECT_EQ(values.at("label.count").get<double>(), std::round(m.at("label.count").value)) << where;
  // float32 on the wire: the stored double rounded to single precision.
  EXPECT_FLOAT_EQ(values.at("bore_to_edge.distance").get<float>(),
                  static_cast<float>(m.at("bore_to_edge.distance").value))
      << where;
  EXPECT_NEAR(values.at("label_angle.angle").get<double>(), m.at("label_angle.angle").value,
              0.005 + 1e-9)
      << where << " (scaled_int16, factor 100)";
}

// A stored row is self-consistent: verdict pass exactly when every checked value is in band.
// An error row is allowed only for a frame the camera delivered incomplete (GVSP packets lost
// on a loaded machine): it must say so and carry no verdict-bearing value.
void expectRowConsistent(const StoredPart& part) {
  const std::string where = "part " + std::to_string(part.partId);
  EXPECT_EQ(part.recipeId, kRecipe) << where;
  if (part.verdict == "error") {
    EXPECT_NE(part.error.find("incomplete frame"), std::string::npos)
        << where << ": " << part.error;
    return;
  }
  bool allPass = true;
  int checked = 0;
  for (const auto& [name, m] : part.measurements) {
    if (m.checked) ++checked;
    if (m.checked && !m.pass) allPass = false;
  }
  EXPECT_GE(checked, 4) << where;
  EXPECT_EQ(part.verdict == "pass", allPass) << where;
  EXPECT_EQ(part.failedChecks.empty() || part.failedChecks == "[]", part.verdict == "pass")
      << where << " failed_checks=" << part.failedChecks;
}

TEST(DaemonLine, FakeGigECameraAndPymodbusPlc) {
  const auto expected = expectedParts(kDemo);
  ASSERT_EQ(expected.size(), 12u);
  ChildProcess camera({FAKE_GIGE_CAMERA_PATH, "--folder", kDemo});
  ASSERT_TRUE(
      camera.waitForLine([](const std::string& l) { return l.rfind("listening", 0) == 0; }, 10s))
      << "the fake GigE camera did not start";

  PlcLine line;
  line.start(
      "  backend: aravis\n  aravis:\n    address: 127.0.0.1\n    pixel_format: Mono8\n"
      "    region: [0, 0, 640, 480]\n    trigger: software\n    colour: mono\n",
      kRecipe);
  constexpr int kParts = 240;  // 20 rounds of the 12 demo images
  ASSERT_NO_FATAL_FAILURE(line.runParts(kParts, 5000ms));
  ASSERT_NO_FATAL_FAILURE(line.stop());

  // The frames the camera served, in order: "frame <k> <raw block id> <file>".
  std::vector<std::pair<std::int64_t, std::string>> served;
  for (const auto& l : camera.lines()) {
    if (l.rfind("frame ", 0) != 0) continue;
    std::istringstream in(l.substr(6));
    std::size_t k = 0;
    std::int64_t raw = 0;
    std::string file;
    in >> k >> raw >> file;
    ASSERT_EQ(k, served.size());
    served.emplace_back(raw, file);
  }
  const auto parts = storedParts(line.database());
  const auto results = line.results();
  ASSERT_EQ(parts.size(), static_cast<std::size_t>(kParts)) << "one row per trigger";
  ASSERT_EQ(results.size(), static_cast<std::size_t>(kParts)) << "one PLC result per trigger";
  EXPECT_EQ(integrityCheck(line.database()), "ok");

  // The first part's frame id is the camera's raw block id (facetd unwraps later ones past the
  // 16-bit wrap); part i took the frame (frame_id_i - frame_id_0) after it.
  std::size_t k0 = served.size();
  for (std::size_t k = 0; k < served.size(); ++k)
    if (served[k].first == parts.front().frameId) k0 = k;
  ASSERT_LT(k0, served.size()) << "the first part's frame was not served by the camera";
  int passes = 0, fails = 0, errors = 0;
  for (std::size_t i = 0; i < parts.size(); ++i) {
    const auto& p = parts[i];
    const std::string where = "part " + std::to_string(p.partId);
    EXPECT_EQ(p.partId, static_cast<std::int64_t>(i) + 1);
    const std::size_t k = k0 + static_cast<std::size_t>(p.frameId - parts.front().frameId);
    ASSERT_LT(k, served.size()) << where << ": frame id " << p.frameId << " never served";
    const std::string& file = served[k].second;
    ASSERT_TRUE(expected.count(file)) << file;
    if (p.verdict != "error") {
      EXPECT_EQ(p.verdict, expected.at(file).verdict) << where << " (" << file << ")";
    }
    EXPECT_TRUE(p.serial.empty() && p.expected.empty())
        << where << ": a live camera has no sidecar";
    expectRowConsistent(p);
    expectRegistersMatch(results[i], p);
    EXPECT_EQ(results[i].at("counter").get<int>(), static_cast<int>((i + 1) % 65536)) << where;
    (p.verdict == "pass" ? passes : p.verdict == "fail" ? fails : errors)++;
  }
  // Incomplete frames are rare on loopback (a starved receive thread on a loaded machine): <= 2 %.
  EXPECT_LE(errors, kParts / 50);
  EXPECT_GE(passes, 180 - errors);
  EXPECT_GE(fails, 60 - errors);
  EXPECT_EQ(passes + fails + errors, kParts);
}

TEST(DaemonLine, ReplayCameraAndPymodbusPlc) {
  const auto expected = expectedParts(kDemo);
  PlcLine line;
  line.start("  backend: replay\n  replay:\n    folder: " + kDemo +
                 "\n    glob: \"*.png\"\n    loop: true\n    trigger: software\n    colour: mono\n",
             kRecipe, "info");
  constexpr int kParts = 36;
  ASSERT_NO_FATAL_FAILURE(line.runParts(kParts, 5000ms));
  ASSERT_NO_FATAL_FAILURE(line.stop());
  // The recipe ran once on its picture of the part before the station reported itself running
  // (and the PLC saw it ready).
  std::string log;
  for (const auto& l : line.facetd().lines()) log += l + "\n";
  const auto warmed = log.find("warmed up on its picture of the part");
  ASSERT_NE(warmed, std::string::npos) << log;
  EXPECT_LT(warmed, log.find(" running: camera ")) << log;
  const auto parts = storedParts(line.database());
  const auto results = line.results();
  ASSERT_EQ(parts.size(), static_cast<std::size_t>(kParts));
  ASSERT_EQ(results.size(), static_cast<std::size_t>(kParts));
  for (std::size_t i = 0; i < parts.size(); ++i) {
    const auto& p = parts[i];
    const std::string file = std::filesystem::path(p.source).filename().string();
    ASSERT_TRUE(expected.count(file)) << p.source;
    // The replay carries the sidecar: serial and expected verdict are stored with the part.
    EXPECT_EQ(p.serial, expected.at(file).serial);
    EXPECT_EQ(p.expected, expected.at(file).verdict);
    EXPECT_EQ(p.verdict, expected.at(file).verdict) << "part " << p.partId << " (" << file << ")";
    expectRowConsistent(p);
    expectRegistersMatch(results[i], p);
  }
}

}  // namespace
}  // namespace facet::daemon_test
