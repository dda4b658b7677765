#pragma once
// The command line of a benchmark over generated scenes: [--smoke] [--scenes N] [--seed N].
// --smoke: a few scenes, for CTest; --scenes: scenes per row; --seed: another set of scenes (the
// figures must not depend on the set they were looked at on).

#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <optional>

namespace facet::bench {

struct SceneRunArgs {
  bool smoke = false;
  int scenes = 0;
  std::uint64_t seed = 1;
};

// The arguments with `scenes` per row by default (`smokeScenes` with --smoke) and seed 1; nothing
// (after printing the usage line with `name`) for any other argument or a count that is not a
// positive number.
inline std::optional<SceneRunArgs> parseSceneRunArgs(int argc, char** argv, const char* name,
                                                     int scenes, int smokeScenes) {
  SceneRunArgs args;
  args.scenes = scenes;
  for (int i = 1; i < argc; ++i) {
    if (!std::strcmp(argv[i], "--smoke")) {
      args.smoke = true;
    } else if (!std::strcmp(argv[i], "--scenes") && i + 1 < argc) {
      args.scenes = std::atoi(argv[++i]);
      if (args.scenes > 0) continue;
      std::fprintf(stderr, "%s: --scenes must be a positive number\n", name);
      return std::nullopt;
    } else if (!std::strcmp(argv[i], "--seed") && i + 1 < argc) {
      args.seed = std::strtoull(argv[++i], nullptr, 10);
    } else {
      std::fprintf(stderr, "usage: %s [--smoke] [--scenes N] [--seed N]\n", name);
      return std::nullopt;
    }
  }
  if (args.smoke) args.scenes = smokeScenes;
  return args;
}

}  // namespace facet::bench
