// Cold start (warm page cache) of the facet tool: wall time from exec to exit, median of N runs,
// for `facet version` (no image: must stay <= 30 ms), `facet match` on a demo image as PNG, TIFF,
// BMP and binary PGM (all read without the image-codec module) and as WebP (which loads
// the module).
// Baseline: the same tool linked with OpenImageIO and OpenCV's imgcodecs, as it was before the
// codecs became a module.
// --smoke: 3 runs per case, same table.
#include <fcntl.h>
#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <string>
#include <vector>

#include <opencv2/imgcodecs.hpp>

extern char** environ;

namespace {

// Milliseconds from spawn to exit; stdout and stderr go to /dev/null. Negative when it failed.
double runOnce(const std::vector<std::string>& args) {
  std::vector<char*> argv;
  for (const auto& a : args) argv.push_back(const_cast<char*>(a.c_str()));
  argv.push_back(nullptr);
  posix_spawn_file_actions_t quiet;
  posix_spawn_file_actions_init(&quiet);
  posix_spawn_file_actions_addopen(&quiet, 1, "/dev/null", O_WRONLY, 0);
  posix_spawn_file_actions_addopen(&quiet, 2, "/dev/null", O_WRONLY, 0);
  const auto start = std::chrono::steady_clock::now();
  pid_t pid = 0;
  const int spawned = posix_spawn(&pid, argv[0], &quiet, nullptr, argv.data(), environ);
  posix_spawn_file_actions_destroy(&quiet);
  if (spawned != 0) return -1;
  int status = 0;
  waitpid(pid, &status, 0);
  const auto end = std::chrono::steady_clock::now();
  if (!WIFEXITED(status) || WEXITSTATUS(status) != 0) return -1;
  return std::chrono::duration<double, std::milli>(end - start).count();
}

double medianMs(const std::vector<std::string>& args, int runs) {
  runOnce(args);  // the page cache warm, as on a running line computer
  std::vector<double> ms;
  for (int i = 0; i < runs; ++i) {
    const double t = runOnce(args);
    if (t < 0) return -1;
    ms.push_back(t);
  }
  std::sort(ms.begin(), ms.end());
  return ms[ms.size() / 2];
}

}  // namespace

int main(int argc, char** argv) {
  const bool smoke = argc > 1 && std::strcmp(argv[1], "--smoke") == 0;
  const int runs = smoke ? 3 : 21;
  const std::vector<std::string> version = {"version"};
  // The repository's demo part and model, wherever the benchmark is run from.
  const std::string root = FACET_SOURCE_DIR;
  const std::string png = root + "/recipes/demo/bracket_shape/part_000.png";
  const auto copyAs = [&](const char* extension) {
    const std::string copy = (std::filesystem::temp_directory_path() /
                              ("bench_startup_" + std::to_string(getpid()) + extension))
                                 .string();
    const cv::Mat part = cv::imread(png, cv::IMREAD_UNCHANGED);
    if (part.empty() || !cv::imwrite(copy, part)) {
      std::fprintf(stderr, "bench_startup: cannot read %s or write %s\n", png.c_str(),
                   copy.c_str());
      std::exit(1);
    }
    return copy;
  };
  const std::string tiff = copyAs(".tif"), bmp = copyAs(".bmp"), pgm = copyAs(".pgm"),
                    webp = copyAs(".webp");
  const std::string model = root + "/recipes/models/bracket.shape";
  const std::vector<std::string> match = {"match", "--model", model, "--image", png};
  const std::vector<std::string> matchTiff = {"match", "--model", model, "--image", tiff};
  const std::vector<std::string> matchBmp = {"match", "--model", model, "--image", bmp};
  const std::vector<std::string> matchPgm = {"match", "--model", model, "--image", pgm};
  const std::vector<std::string> matchWebp = {"match", "--model", model, "--image", webp};
  std::printf("bench_startup%s: median wall time of %d runs (warm page cache)\n",
              smoke ? " --smoke" : "", runs);
  std::printf("%-18s %12s %22s %8s\n", "command", "facet ms", "linked codecs ms", "ratio");
  int failed = 0;
  for (const auto& [name, args] :
       {std::pair{"version", version}, std::pair{"match png", match},
        std::pair{"match tiff", matchTiff}, std::pair{"match bmp", matchBmp},
        std::pair{"match pgm", matchPgm}, std::pair{"match webp (module)", matchWebp}}) {
    std::vector<std::string> now = {FACET_TOOL}, old = {FACET_LINKED_CODECS_TOOL};
    now.insert(now.end(), args.begin(), args.end());
    old.insert(old.end(), args.begin(), args.end());
    const double t = medianMs(now, runs), baseline = medianMs(old, runs);
    if (t < 0 || baseline < 0) {
      std::printf("%-18s failed\n", name);
      ++failed;
      continue;
    }
    std::printf("%-18s %12.1f %22.1f %7.2fx\n", name, t, baseline, baseline / t);
  }
  std::filesystem::remove(tiff);
  std::filesystem::remove(bmp);
  std::filesystem::remove(pgm);
  std::filesystem::remove(webp);
  return failed == 0 ? 0 : 1;
}
