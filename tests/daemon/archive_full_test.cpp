// facetd with its image archive on a full disk: a 2 MB tmpfs, mounted in a private user+mount
// namespace (unshare -rm) that only facetd sees, almost filled by another file before facetd
// starts. Every part must still be inspected and stored with its verdict, /healthz and /metrics
// must report the archive as degraded, the log must say why, and no half-written file may be
// left looking like an image. Then the other file is deleted (through /proc/<pid>/root, the
// test's way into facetd's mount namespace): the archive must recover and stay healthy under
// its 1 MB quota.
#include <gtest/gtest.h>

#include <algorithm>
#include <csignal>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <thread>

#include <opencv2/imgcodecs.hpp>

#include "tests/daemon/child_process.hpp"
#include "tests/daemon/facetd_http.hpp"
#include "tests/daemon/line_run.hpp"

namespace facet::daemon_test {
namespace {

using namespace std::chrono_literals;
namespace fs = std::filesystem;
const std::string kDemo = std::string(FACET_SOURCE_DIR) + "/recipes/demo/bracket_shape";
const std::string kUnshare = "/usr/bin/unshare";
// Mounts a tmpfs of size $1 on $2, fills $3 KiB of it with $2/filler.bin, then runs the rest.
const std::string kMountThenRun =
    "mount -t tmpfs -o size=\"$1\" tmpfs \"$2\" && "
    "dd if=/dev/zero of=\"$2/filler.bin\" bs=1024 count=\"$3\" status=none && "
    "shift 3 && exec \"$@\"";

std::string readFile(const std::string& file) {
  std::ostringstream s;
  s << std::ifstream(file).rdbuf();
  return s.str();
}

// Whether this machine lets the test mount a tmpfs in a user+mount namespace; `why` otherwise.
bool tmpfsNamespaceWorks(const TempDir& dir, std::string* why) {
  fs::create_directories(dir / "probe");
  ChildProcess probe(
      {kUnshare, "-rm", "sh", "-c", kMountThenRun, "sh", "64k", dir / "probe", "1", "/bin/true"},
      {}, dir / "probe.stderr");
  const auto code = probe.wait(10s);
  if (code == std::optional<int>(0)) return true;
  *why = "unshare -rm + mount -t tmpfs failed (exit " + (code ? std::to_string(*code) : "timeout") +
         "): " + readFile(dir / "probe.stderr");
  return false;
}

// Every file in the archive (seen from inside facetd's mount namespace) is a complete PNG, or
// the filler: no ".partial" or truncated file survives a failed write. facetd goes on writing
// meanwhile, so a ".partial" may be seen mid-write (it must be gone soon after: a PNG write
// takes milliseconds, the 10 s allow for an instrumented facetd on a loaded machine), and the
// quota may remove a file between listing and reading it.
void expectOnlyWholeImages(const std::string& archive, int* images) {
  *images = 0;
  std::vector<fs::path> others;
  for (const auto& entry : fs::recursive_directory_iterator(archive)) {
    if (!entry.is_regular_file() || entry.path().filename() == "filler.bin") continue;
    if (entry.path().extension() != ".png") {
      others.push_back(entry.path());
      continue;
    }
    const std::string name = entry.path().string();
    if (cv::imread(name, cv::IMREAD_UNCHANGED).empty() && fs::exists(name))
      ADD_FAILURE() << "not a whole PNG: " << name;
    ++*images;
  }
  const auto until = std::chrono::steady_clock::now() + 10s;
  for (const auto& file : others) {
    while (fs::exists(file) && std::chrono::steady_clock::now() < until)
      std::this_thread::sleep_for(50ms);
    EXPECT_FALSE(fs::exists(file)) << "left behind: " << file;
  }
}

TEST(ArchiveFull, InspectionGoesOnArchiveDegradedThenRecovers) {
  TempDir dir;
  std::string why;
  if (!tmpfsNamespaceWorks(dir, &why)) GTEST_SKIP() << "SKIPPED, no private tmpfs: " << why;

  // Archive every part (keep: all, two PNGs of ~100 KB each) under a 1 MB quota on a 2 MB disk
  // of which another file takes 1.8 MB.
  const auto station = writeStationFile(
      dir.path(),
      "  backend: replay\n  replay:\n    folder: " + kDemo +
          "\n    glob: \"*.png\"\n    loop: true\n    fps: 10\n    trigger: free_run\n"
          "    colour: mono\n",
      0, {.archiveKeep = "all", .archiveQuotaMb = 1});
  fs::create_directories(dir / "archive");
  ChildProcess facetd({kUnshare,
                       "-rm",
                       "sh",
                       "-c",
                       kMountThenRun,
                       "sh",
                       "2m",
                       dir / "archive",
                       "1800",
                       FACETD_PATH,
                       "--config",
                       station,
                       "--recipe",
                       "2",
                       "--no-plc",
                       "--block-when-behind",
                       "--http-port-file",
                       dir / "http.port",
                       "--log-level",
                       "info"},
                      {}, dir / "facetd.stderr");
  const auto port = waitForHttpPort(dir / "http.port", 30s);
  ASSERT_TRUE(port) << "facetd did not start: " << readFile(dir / "facetd.stderr");
  // unshare and sh exec: the child is facetd itself, and its root shows its mounts.
  const std::string archive = "/proc/" + std::to_string(facetd.pid()) + "/root" + dir / "archive";
  ASSERT_TRUE(fs::exists(archive + "/filler.bin")) << "the tmpfs is not visible at " << archive;
  const std::string db = dir / "results.db";

  // 1. Degraded: the disk is full, parts go on.
  ASSERT_TRUE(waitForStored(
      db, [](const auto& p) { return p.size() >= 10; }, 30s))
      << "fewer than 10 parts stored within 30 s on a full archive disk";
  auto health = healthz(*port);
  ASSERT_TRUE(health.contains("archive")) << health.dump();
  EXPECT_EQ(health["status"], "degraded") << health.dump();
  EXPECT_EQ(health["archive"]["degraded"], true) << health.dump();
  const std::string lastError = health["archive"]["last_error"];
  EXPECT_NE(lastError.find("No space left on device"), std::string::npos) << lastError;
  EXPECT_NE(lastError.find(dir / "archive/"), std::string::npos) << "names no file: " << lastError;
  EXPECT_EQ(metricValue(httpGet(*port, "/metrics").value_or(""), "facet_archive_degraded"), 1.0);
  EXPECT_TRUE(facetd.waitForLine(
      [](const std::string& l) {
        return l.find("archive degraded:") != std::string::npos &&
               l.find("No space left on device") != std::string::npos;
      },
      1s))
      << "no log line saying the archive is degraded";
  int imagesWhileFull = 0;
  ASSERT_NO_FATAL_FAILURE(expectOnlyWholeImages(archive, &imagesWhileFull));

  // 2. Space comes back: the next archived part clears the state, and the quota keeps it so.
  fs::remove(archive + "/filler.bin");
  ASSERT_TRUE(facetd.waitForLine(
      [](const std::string& l) { return l.find("archive writable again") != std::string::npos; },
      10s))
      << "the archive did not recover once space was freed";
  const std::int64_t recoveredAfter = storedParts(db).back().partId;
  ASSERT_TRUE(waitForStored(
      db, [&](const auto& p) { return !p.empty() && p.back().partId >= recoveredAfter + 15; },
      30s));
  health = healthz(*port);
  EXPECT_EQ(health["archive"]["degraded"], false) << health.dump();
  EXPECT_EQ(health["status"], "ok") << health.dump();
  EXPECT_EQ(metricValue(httpGet(*port, "/metrics").value_or(""), "facet_archive_degraded"), 0.0);
  EXPECT_LE(health["archive"]["bytes"].get<double>(), 1.3 * 1024 * 1024) << "quota ignored";
  int imagesAfter = 0;
  ASSERT_NO_FATAL_FAILURE(expectOnlyWholeImages(archive, &imagesAfter));
  EXPECT_GE(imagesAfter, 4) << "nothing archived after the recovery";

  facetd.signal(SIGTERM);
  const auto code = facetd.wait(20s);
  ASSERT_TRUE(code) << "facetd did not exit after SIGTERM";
  EXPECT_EQ(*code, 0) << readFile(dir / "facetd.stderr");

  // 3. Every part taken is stored, with the demo's verdict: the full disk cost no inspection.
  const auto parts = storedParts(db);
  EXPECT_EQ(integrityCheck(db), "ok");
  const auto expected = expectedParts(kDemo);
  for (std::size_t i = 0; i < parts.size(); ++i) {
    const auto& p = parts[i];
    ASSERT_EQ(p.partId, static_cast<std::int64_t>(i) + 1) << "part ids have a hole";
    const std::string file = fs::path(p.source).filename().string();
    ASSERT_TRUE(expected.count(file)) << p.source;
    EXPECT_EQ(p.verdict, expected.at(file).verdict)
        << "part " << p.partId << " (" << file << ") " << p.error;
  }
  std::cout << "[ figures  ] " << parts.size() << " parts stored; " << imagesWhileFull
            << " archive images on the full disk, " << imagesAfter
            << " after the recovery; last error while full: " << lastError << "\n";
}

}  // namespace
}  // namespace facet::daemon_test
