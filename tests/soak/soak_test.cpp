// The CI soak: 2,000 parts through the real facetd (looped replay of the fiducial-board demo,
// free run, no PLC). Asserts that resident memory, open fds and threads do not grow after the
// warm-up and that every part is stored with its recorded verdict. Latency is printed, not
// asserted (timing is for benchmarks, and CI machines are shared); tests/soak/run-soak.sh runs
// the 100,000-part soak, which judges the p99 too.
#include <iostream>

#include <gtest/gtest.h>

#include "tests/soak/soak_run.hpp"

namespace facet::soak {
namespace {

SoakOptions demoSoak() {
  SoakOptions o;
  o.facetd = FACETD_PATH;
  o.replayFolder = FACET_SOURCE_DIR "/recipes/demo/fiducial_board";
  o.recipesFolder = FACET_SOURCE_DIR "/recipes";
  o.calibrationFile = FACET_SOURCE_DIR "/recipes/calibration.yaml";
  return o;
}

TEST(Soak, TwoThousandPartsKeepMemoryFdsAndThreadsFlat) {
  SoakOptions o = demoSoak();
  o.parts = 2000;
  o.windows = 10;
  o.warmupWindows = 4;    // allocator arenas grow over the first ~500-800 parts
  o.baselineWindows = 3;  // RSS dips by ~10 MiB for a window now and then: three in a row rarely
  // A window lasts about 0.5 s on an idle machine: sample often enough that each has several
  // samples (a window without one fails the judgement; seen once with 250 ms under CI load).
  o.samplePeriod = std::chrono::milliseconds(50);
  o.maxP99Ratio = 0;      // printed, not judged here
  o.archiveQuotaMb = 20;  // about 130 images: eviction runs for most of the test
  o.timeout = std::chrono::seconds(150);
  const SoakReport r = runSoak(o);
  printSoakReport(std::cout, o, r);

  EXPECT_EQ(r.exitCode, 0);
  EXPECT_EQ(r.partsStored, o.parts);
  EXPECT_EQ(r.partsMissing, 0u);
  EXPECT_EQ(r.errorParts, 0u);
  EXPECT_EQ(r.unexpected, 0u);
  EXPECT_EQ(r.integrity, "ok");
  EXPECT_GT(r.archiveFiles, 0u);              // 500 failed parts were archived...
  EXPECT_LE(r.archiveMiB, o.archiveQuotaMb);  // ...and the oldest evicted to stay in the quota
  ASSERT_EQ(r.windows.size(), static_cast<std::size_t>(o.windows));
  for (std::size_t k = static_cast<std::size_t>(o.warmupWindows); k < r.windows.size(); ++k)
    ASSERT_GT(r.windows[k].samples, 0) << "window " << k + 1 << " was not sampled";
  EXPECT_LE(r.rssGrowth, 0.05);
  EXPECT_LE(r.fdGrowth, 0);
  EXPECT_LE(r.threadGrowth, 0);
  EXPECT_TRUE(r.ok()) << r.failures.front();
}

// The judgement must be able to fail: facetd with a shim that leaks one fd per opened PNG.
TEST(Soak, InjectedFdLeakFailsTheJudgement) {
  SoakOptions o = demoSoak();
  o.parts = 400;
  o.windows = 4;
  o.warmupWindows = 1;
  o.baselineWindows = 1;
  o.samplePeriod = std::chrono::milliseconds(200);
  o.maxP99Ratio = 0;
  o.timeout = std::chrono::seconds(100);
  o.environment = {{"LD_PRELOAD", LEAK_SHIM_PATH}, {"FACET_LEAK_FDS", "1"}};
  const SoakReport r = runSoak(o);
  printSoakReport(std::cout, o, r);

  EXPECT_EQ(r.partsStored, o.parts);  // facetd itself still works...
  EXPECT_GE(r.fdGrowth, 100);         // ...but 200 parts later it holds about 200 more fds
  EXPECT_FALSE(r.ok());
}

}  // namespace
}  // namespace facet::soak
