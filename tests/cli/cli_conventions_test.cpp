// What a line engineer meets first: `facet` and `facetd` used wrongly. The README promises exit
// code 1 for bad input and 2 for a failed measurement, errors naming the option or file in the
// user's words, and nothing from the libraries underneath on stderr.
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <string>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "tests/support/cli/facet_cli.hpp"
#include "tests/support/scene/scene.hpp"

namespace {

namespace fs = std::filesystem;
using facet::test::CliRun;

CliRun facet(const std::string& args) {
  return facet::test::runFacet(args);
}

CliRun facetd(const std::string& args) {
  const std::string command = std::string(FACETD) + " " + args + " 2>&1";
  CliRun run;
  FILE* pipe = ::popen(command.c_str(), "r");
  if (pipe == nullptr) return run;
  char buffer[4096];
  while (const std::size_t n = std::fread(buffer, 1, sizeof buffer, pipe))
    run.out.append(buffer, n);
  const int status = ::pclose(pipe);
  run.exitCode = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  return run;
}

bool has(const std::string& text, const std::string& part) {
  return text.find(part) != std::string::npos;
}

// Nothing a library prints on its own: OpenCV's log lines, libpng's error handler.
void expectQuietLibraries(const CliRun& r) {
  EXPECT_FALSE(has(r.err, "[ WARN")) << r.err;
  EXPECT_FALSE(has(r.err, "libpng")) << r.err;
  EXPECT_FALSE(has(r.err, "global ")) << r.err;
}

class CliConventions : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = fs::temp_directory_path() / ("facet_cli_conventions_" + std::to_string(::getpid()));
    fs::create_directories(dir_);
    facet::scene::SceneSpec spec;
    spec.size = {160, 140};
    spec.background = 200;
    spec.blurSigma = 1.0;
    spec.noiseSigma = 1.0;
    facet::scene::Scene s(spec);
    s.addDisc({80.4, 69.7}, 30.2, 40);  // a dark hole in a light plate
    hole_ = (dir_ / "hole.png").string();
    s.write(hole_);
  }
  void TearDown() override { fs::remove_all(dir_); }

  fs::path dir_;
  std::string hole_;
};

TEST_F(CliConventions, NoCommandIsBadInputListingTheCommands) {
  const CliRun r = facet("");
  EXPECT_EQ(r.exitCode, 1);
  EXPECT_TRUE(has(r.err, "circle") && has(r.err, "match") && has(r.err, "recipe")) << r.err;
  const CliRun recipe = facet("recipe");
  EXPECT_EQ(recipe.exitCode, 1);
  EXPECT_TRUE(has(recipe.err, "check") && has(recipe.err, "train")) << recipe.err;
}

TEST_F(CliConventions, UnknownCommandIsNamedWithTheNearestOne) {
  const CliRun bogus = facet("bogus");
  EXPECT_EQ(bogus.exitCode, 1);
  EXPECT_TRUE(has(bogus.err, "unknown command 'bogus'")) << bogus.err;
  EXPECT_FALSE(has(bogus.err, "A subcommand is required")) << bogus.err;

  const CliRun typo = facet("circel --image x.png");
  EXPECT_EQ(typo.exitCode, 1);
  EXPECT_TRUE(has(typo.err, "did you mean 'circle'")) << typo.err;

  const CliRun nested = facet("recipe chek x.yaml");
  EXPECT_EQ(nested.exitCode, 1);
  EXPECT_TRUE(has(nested.err, "did you mean 'check'")) << nested.err;
}

TEST_F(CliConventions, HelpExitsZero) {
  EXPECT_EQ(facet("--help").exitCode, 0);
  EXPECT_EQ(facet("circle --help").exitCode, 0);
  EXPECT_EQ(facetd("--help").exitCode, 0);
}

TEST_F(CliConventions, ArgumentErrorsExitOneAndNameTheOption) {
  const CliRun number = facet("circle --image " + hole_ + " --centre 80,70 --radius abc");
  EXPECT_EQ(number.exitCode, 1);
  EXPECT_TRUE(has(number.err, "--radius")) << number.err;

  const CliRun missing = facet("circle --image " + hole_ + " --radius 30");
  EXPECT_EQ(missing.exitCode, 1);
  EXPECT_TRUE(has(missing.err, "--centre")) << missing.err;

  const CliRun both = facet("results export --db " + (dir_ / "r.db").string() + " --csv --json");
  EXPECT_EQ(both.exitCode, 1);
  EXPECT_TRUE(has(both.err, "--json") && has(both.err, "--csv")) << both.err;

  const CliRun extra = facet("version --frobnicate");
  EXPECT_EQ(extra.exitCode, 1);
  EXPECT_TRUE(has(extra.err, "--frobnicate")) << extra.err;
}

TEST_F(CliConventions, DaemonArgumentErrorsExitOne) {
  const CliRun replay = facetd("--config recipes/station.yaml --replay /nonexistent/folder");
  EXPECT_EQ(replay.exitCode, 1) << replay.out;
  EXPECT_TRUE(has(replay.out, "/nonexistent/folder")) << replay.out;
  const CliRun none = facetd("");
  EXPECT_EQ(none.exitCode, 1) << none.out;
  EXPECT_TRUE(has(none.out, "--config")) << none.out;
}

TEST_F(CliConventions, MissingImageSaysNoSuchFileAndNothingElse) {
  const std::string missing = (dir_ / "nope.png").string();
  for (const std::string& command :
       {"circle --image " + missing + " --centre 80,70 --radius 30", "edges --image " + missing,
        "model create --image " + missing + " --out " + (dir_ / "m.model").string(),
        "register --ref " + missing + " --image " + hole_}) {
    const CliRun r = facet(command);
    EXPECT_EQ(r.exitCode, 1) << command;
    EXPECT_TRUE(has(r.err, missing + ": no such file")) << command << "\n" << r.err;
    expectQuietLibraries(r);
  }
}

TEST_F(CliConventions, CorruptImagesGetOurMessageOnly) {
  // A PNG cut in half (libpng's default handler prints "libpng error: Read Error") and a text
  // file named .png (OpenCV logs a findDecoder warning).
  std::ifstream in(hole_, std::ios::binary);
  const std::string bytes{std::istreambuf_iterator<char>(in), {}};
  const fs::path truncated = dir_ / "truncated.png";
  std::ofstream(truncated, std::ios::binary) << bytes.substr(0, bytes.size() / 2);
  const fs::path text = dir_ / "notes.png";
  std::ofstream(text) << "this is not an image\n";
  for (const fs::path& file : {truncated, text}) {
    const CliRun r = facet("circle --image " + file.string() + " --centre 80,70 --radius 30");
    EXPECT_EQ(r.exitCode, 1) << r.err;
    EXPECT_TRUE(has(r.err, file.string() + ":")) << r.err;
    expectQuietLibraries(r);
  }
}

TEST_F(CliConventions, CircleTakesTheRecipeWords) {
  for (const std::string words :
       {"--centre 80,70 --polarity dark_inside", "--center 80,70 --polarity dark_inside",
        "--centre 80,70 --polarity dark_to_light"}) {
    const CliRun r = facet("circle --image " + hole_ + " --radius 30 --json " + words);
    ASSERT_EQ(r.exitCode, 0) << words << "\n" << r.err;
    EXPECT_NEAR(nlohmann::json::parse(r.out).at("radius").get<double>(), 30.2, 0.05) << words;
  }
  // The wrong polarity finds no rim: the words mean what the recipe means.
  const CliRun light =
      facet("circle --image " + hole_ + " --radius 30 --centre 80,70 --polarity light_inside");
  EXPECT_EQ(light.exitCode, 2) << light.err;
}

TEST_F(CliConventions, NumbersPrintReadably) {
  const CliRun text = facet("circle --image " + hole_ + " --radius 30 --centre 80,70");
  ASSERT_EQ(text.exitCode, 0) << text.err;
  EXPECT_FALSE(has(text.out, "000000")) << text.out;

  const CliRun outside = facet("circle --image " + hole_ + " --radius 20 --centre 600,600");
  EXPECT_EQ(outside.exitCode, 2);
  EXPECT_TRUE(has(outside.err, "(600, 600)")) << outside.err;
  EXPECT_FALSE(has(outside.err, "000000")) << outside.err;
}

}  // namespace
