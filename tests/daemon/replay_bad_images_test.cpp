// facetd replaying a folder where bad files sit between recorded parts: truncated, zero-byte,
// text and TIFF bytes behind image extensions, and headers announcing 30000 x 30000 and
// 16000 x 16000 x RGB16 pixels with no data behind them. Each bad file must become a part stored
// as "error" (not inspected) under its own file name, with a log line naming it; none may crash
// facetd or be reported good; the good parts around them keep their recorded verdicts; and the
// peak resident memory of facetd stays far below what the headers announce. (The camera-level
// version of this test is tests/hardening/replay_faults_test.cpp; the bad files are the same.)
#include <gtest/gtest.h>
#include <sys/resource.h>

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <sstream>

#include <opencv2/imgcodecs.hpp>

#include "tests/daemon/child_process.hpp"
#include "tests/daemon/line_run.hpp"
#include "tests/hardening/bad_image_files.hpp"
#include "tests/support/process/peak_resident_memory.hpp"

namespace facet::daemon_test {
namespace {

using namespace std::chrono_literals;
namespace fs = std::filesystem;
const std::string kDemo = std::string(FACET_SOURCE_DIR) + "/recipes/demo/bracket_shape";

std::string readFile(const std::string& file) {
  std::ostringstream s;
  s << std::ifstream(file, std::ios::binary).rdbuf();
  return s.str();
}

// The largest peak resident memory of the children this test has waited for, bytes.
std::uint64_t childrenPeakResidentBytes() {
  rusage usage{};
  ::getrusage(RUSAGE_CHILDREN, &usage);
  return static_cast<std::uint64_t>(usage.ru_maxrss) * 1024;
}

// How much the bad files may add to facetd's peak RSS. The 16000 x 16000 x RGB16 header passes
// the pixel limit, so its decoder reserves 1.5 GB that it never fills; AddressSanitizer writes
// the shadow of that reservation (1/8 of it), which a release build never touches.
#ifdef __SANITIZE_ADDRESS__
constexpr std::uint64_t kAllowedGrowth = std::uint64_t{256} << 20;
#else
constexpr std::uint64_t kAllowedGrowth = std::uint64_t{128} << 20;
#endif

struct ReplayRun {
  int exitCode = -1;
  std::uint64_t sampledPeak = 0;  // the largest VmHWM read while facetd ran
  std::vector<std::string> stdoutLines;
  std::vector<StoredPart> parts;
};

// facetd --replay over `folder`, once; VmHWM is read every 20 ms until it exits.
ReplayRun replay(const TempDir& dir, const std::string& folder, const std::string& name) {
  const auto station = writeStationFile(
      dir.path() + "/" + name,
      "  backend: replay\n  replay:\n    folder: " + kDemo + "\n    glob: \"*.png\"\n", 0);
  ChildProcess facetd({FACETD_PATH, "--config", station, "--recipe", "2", "--no-plc", "--replay",
                       folder, "--print-parts", "--log-level", "info"},
                      {}, dir / (name + "/facetd.stderr"));
  ReplayRun run;
  const auto until = std::chrono::steady_clock::now() + 60s;
  std::optional<int> code;
  while (!code && std::chrono::steady_clock::now() < until) {
    run.sampledPeak = std::max(run.sampledPeak, test::peakResidentBytes(facetd.pid()));
    code = facetd.wait(20ms);
  }
  run.exitCode = code.value_or(-1);
  facetd.waitForLine([](const std::string&) { return false; }, 2s);  // stdout drained
  run.stdoutLines = facetd.lines();
  run.parts = storedParts(dir / (name + "/results.db"));
  return run;
}

struct RecordedFile {
  std::string name;
  std::string expected;  // the sidecar's verdict for good files, "error" for bad ones
};

TEST(ReplayBadImages, EachBadFileIsAnErrorPartNamedByItsFileAndGoodOnesAreInspected) {
  TempDir dir;
  const std::string good = dir / "good", bad = dir / "bad";
  for (const auto& d : {good, bad, dir / "good-run", dir / "bad-run"}) fs::create_directories(d);
  const auto sidecars = expectedParts(kDemo);

  // Both folders hold the same seven recorded parts (pass and fail); `bad` has the bad files
  // between them. Names sort naturally in the order listed.
  std::vector<RecordedFile> files;
  auto addGood = [&](const std::string& name, const std::string& demo) {
    for (const auto& folder : {good, bad}) {
      fs::copy_file(kDemo + "/" + demo, folder + "/" + name);
      fs::copy_file(kDemo + "/" + demo + ".json", folder + "/" + name + ".json");
    }
    files.push_back({name, sidecars.at(demo).verdict});
  };
  // A recorded part the in-process readers leave to the image-codec module (an ASCII PGM,
  // camera/pgm_file.hpp): both runs load the module, so that the baseline holds its memory too.
  // (facetd writes its PNGs without it, and the bad files are what made the other run load it:
  // the difference then measured the module, not the bad files.)
  auto addGoodThroughModule = [&](const std::string& name, const std::string& demo) {
    const cv::Mat pixels = cv::imread(kDemo + "/" + demo, cv::IMREAD_UNCHANGED);
    for (const auto& folder : {good, bad}) {
      ASSERT_TRUE(cv::imwrite(folder + "/" + name, pixels, {cv::IMWRITE_PXM_BINARY, 0}));
      fs::copy_file(kDemo + "/" + demo + ".json", folder + "/" + name + ".json");
    }
    files.push_back({name, sidecars.at(demo).verdict});
  };
  auto addBad = [&](const std::string& name, const std::string& bytes) {
    std::ofstream(bad + "/" + name, std::ios::binary) << bytes;
    files.push_back({name, "error"});
  };
  const std::string demoPng = readFile(kDemo + "/part_001.png");
  addGood("p01.png", "part_000.png");
  addBad("p02_truncated.png", demoPng.substr(0, demoPng.size() / 2));
  // A truncated recording keeps its sidecar: expected pass, and still never reported good.
  fs::copy_file(kDemo + "/part_001.png.json", bad + "/p02_truncated.png.json");
  addGood("p03.png", "part_003.png");
  addBad("p04_zero_bytes.png", "");
  addBad("p05_text_named_png.png", "serial;verdict\n4711;good\n");
  addGood("p06.png", "part_004.png");
  addBad("p07_huge_30000x30000.png", test::pngHeaderOnly(30000, 30000, 8, 0));
  addBad("p08_huge_16000x16000_rgb16.png", test::pngHeaderOnly(16000, 16000, 16, 2));
  addGood("p09.png", "part_007.png");
  addBad("p10_huge.pgm", "P5\n30000 30000\n255\n\x01\x02");
  addBad("p11_tiff_named_bmp.bmp", std::string("II*\0garbage", 11));
  addGood("p12.png", "part_008.png");
  addGood("p13.png", "part_011.png");
  addGoodThroughModule("p14_ascii.pgm", "part_002.png");
  constexpr std::size_t kBad = 7, kGood = 7;
  ASSERT_EQ(files.size(), kBad + kGood);

  // The good folder alone first: the memory facetd needs anyway, as the baseline.
  const ReplayRun baseline = replay(dir, good, "good-run");
  ASSERT_EQ(baseline.exitCode, 0) << readFile(dir / "good-run/facetd.stderr");
  ASSERT_EQ(baseline.parts.size(), kGood);
  const std::uint64_t peakGood = childrenPeakResidentBytes();

  const ReplayRun run = replay(dir, bad, "bad-run");
  const std::uint64_t peakBoth = childrenPeakResidentBytes();  // max of both runs
  EXPECT_EQ(run.exitCode, 0) << "facetd crashed or failed: "
                             << readFile(dir / "bad-run/facetd.stderr");
  ASSERT_EQ(run.parts.size(), files.size()) << "one stored part per recorded file";

  std::size_t errors = 0;
  for (std::size_t i = 0; i < files.size(); ++i) {
    const auto& p = run.parts[i];
    const auto& f = files[i];
    const std::string where = "part " + std::to_string(p.partId) + " (" + f.name + ")";
    EXPECT_EQ(p.partId, static_cast<std::int64_t>(i) + 1);
    EXPECT_EQ(fs::path(p.source).filename().string(), f.name) << where;
    EXPECT_EQ(p.verdict, f.expected) << where << ": " << p.error;
    if (f.expected != "error") continue;
    ++errors;
    EXPECT_NE(p.error.find("not inspected"), std::string::npos) << where << ": " << p.error;
    EXPECT_NE(p.error.find(f.name), std::string::npos) << where << ": " << p.error;
    EXPECT_TRUE(p.measurements.empty()) << where << " has measurements";
    // Each refusal is logged, naming the file.
    const bool logged =
        std::any_of(run.stdoutLines.begin(), run.stdoutLines.end(), [&](const std::string& l) {
          return l.find("error") != std::string::npos &&
                 l.find("replay: skipping " + bad + "/" + f.name) != std::string::npos;
        });
    EXPECT_TRUE(logged) << "no log line naming " << f.name;
  }
  EXPECT_EQ(errors, kBad);
  EXPECT_EQ(run.parts[1].serial, sidecars.at("part_001.png").serial) << "sidecar of a bad file";
  EXPECT_EQ(run.parts[1].expected, "pass");
  // The summary --print-parts ends with counts the bad files as errors, not as good, and the
  // truncated recording (whose sidecar expects "pass") as unexpected.
  std::map<std::string, int> counts;
  for (const auto& f : files) ++counts[f.expected];
  const std::string summary = "summary:  error=" + std::to_string(counts["error"]) +
                              "  fail=" + std::to_string(counts["fail"]) +
                              "  pass=" + std::to_string(counts["pass"]) + "  unexpected=1";
  EXPECT_NE(std::find(run.stdoutLines.begin(), run.stdoutLines.end(), summary),
            run.stdoutLines.end())
      << "no line \"" << summary << "\"";

  // Memory: 30000 x 30000 would be 900 MB, 16000 x 16000 x RGB16 1.5 GB, if ever allocated and
  // touched. The peak must stay under 1 GiB and near that of the good files alone.
  EXPECT_GT(run.sampledPeak, 0u);
  // The kernel hands the parent the child's high-water mark as accounted at exit, which can lag
  // /proc's VmHWM by a few hundred kB (seen: 232 kB of 158 MiB): a margin of 1 MiB.
  EXPECT_LE(run.sampledPeak, peakBoth + (std::uint64_t{1} << 20))
      << "VmHWM read while running exceeds the final peak";
  EXPECT_LT(peakBoth, std::uint64_t{1} << 30) << "peak RSS " << (peakBoth >> 20) << " MiB";
  EXPECT_LT(peakBoth - peakGood, kAllowedGrowth)
      << "the bad files raised facetd's peak RSS from " << (peakGood >> 20) << " to "
      << (peakBoth >> 20) << " MiB";
  std::cout << "[ figures  ] facetd peak RSS: good files only " << (peakGood >> 20)
            << " MiB, with the bad files " << (peakBoth >> 20) << " MiB (max VmHWM sampled "
            << (run.sampledPeak >> 20) << " MiB); " << errors << " bad files stored as error\n";
}

}  // namespace
}  // namespace facet::daemon_test
