// facet_soak: runs facetd over a looped replay for many parts and prints the soak table and
// verdict (see soak_run.hpp). Exit 0 when every bound holds, 1 otherwise, 2 on a usage or
// start-up error. tests/soak/run-soak.sh runs it for the 100,000-part soak.
#include <iostream>

#include <CLI/CLI.hpp>

#include "tests/soak/soak_run.hpp"

int main(int argc, char** argv) {
  using namespace facet::soak;
  SoakOptions o;
  o.facetd = FACETD_PATH;
  o.replayFolder = FACET_SOURCE_DIR "/recipes/demo/fiducial_board";
  o.recipesFolder = FACET_SOURCE_DIR "/recipes";
  o.calibrationFile = FACET_SOURCE_DIR "/recipes/calibration.yaml";
  o.progress = true;
  int sampleMs = 2000;
  int timeoutS = 3600;
  CLI::App app{"facet_soak: facetd over a looped replay, sampled for memory, fds and latency",
               "facet_soak"};
  // run-soak.sh passes its defaults first: a repeated option takes the last value.
  app.option_defaults()->multi_option_policy(CLI::MultiOptionPolicy::TakeLast);
  app.add_option("--facetd", o.facetd, "facetd binary")->check(CLI::ExistingFile);
  app.add_option("--parts", o.parts, "Parts to run")->capture_default_str();
  app.add_option("--windows", o.windows, "Table rows (equal part counts)")->capture_default_str();
  app.add_option("--warmup-windows", o.warmupWindows, "Windows left out of the judgement")
      ->capture_default_str();
  app.add_option("--baseline-windows", o.baselineWindows,
                 "Windows after the warm-up the last one is compared with")
      ->capture_default_str();
  app.add_option("--sample-ms", sampleMs, "Sampling period (ms)")->capture_default_str();
  app.add_option("--recipe", o.recipe, "Recipe id")->capture_default_str();
  app.add_option("--replay", o.replayFolder, "Recorded folder to loop")
      ->check(CLI::ExistingDirectory)
      ->capture_default_str();
  app.add_option("--recipes", o.recipesFolder, "Recipes folder")
      ->check(CLI::ExistingDirectory)
      ->capture_default_str();
  app.add_option("--calibration", o.calibrationFile, "Calibration file")
      ->check(CLI::ExistingFile)
      ->capture_default_str();
  app.add_option("--work-dir", o.workDir, "Keep station file, database, archive and log here")
      ->capture_default_str();
  app.add_option("--archive-quota-mb", o.archiveQuotaMb, "Archive quota")->capture_default_str();
  app.add_option("--max-rss-growth", o.maxRssGrowth, "Bound, fraction")->capture_default_str();
  app.add_option("--max-fd-growth", o.maxFdGrowth, "Bound, fds")->capture_default_str();
  app.add_option("--max-thread-growth", o.maxThreadGrowth, "Bound, threads")->capture_default_str();
  app.add_option("--max-p99-ratio", o.maxP99Ratio, "Bound on the p99 ratio (0: not judged)")
      ->capture_default_str();
  app.add_option("--timeout-s", timeoutS,
                 "Stop facetd (SIGTERM) after this long and report the parts reached")
      ->capture_default_str();
  CLI11_PARSE(app, argc, argv);
  o.samplePeriod = std::chrono::milliseconds(sampleMs);
  o.timeout = std::chrono::seconds(timeoutS);
  try {
    const SoakReport report = runSoak(o);
    printSoakReport(std::cout, o, report);
    return report.ok() ? 0 : 1;
  } catch (const std::exception& e) {
    std::cerr << "facet_soak: " << e.what() << "\n";
    return 2;
  }
}
