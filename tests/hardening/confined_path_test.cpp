// Recipe paths stay inside the recipes folder (config/confined_path.hpp): `..`, absolute paths
// and symbolic links, including links whose target does not exist yet. A dangling link matters
// because `facet recipe train` writes the model file a recipe names: a link pointing out of the
// folder would make it write anywhere the daemon's user may write.

#include <filesystem>
#include <fstream>
#include <random>
#include <string>
#include <variant>

#include <gtest/gtest.h>

#include "config/confined_path.hpp"

namespace {

namespace fs = std::filesystem;
using facet::config::confinedPath;

class Scratch {
 public:
  Scratch() {
    std::random_device rd;
    path_ = fs::temp_directory_path() / ("facet_confined_" + std::to_string(rd()));
    fs::create_directories(path_);
    path_ = fs::canonical(path_);
  }
  ~Scratch() {
    std::error_code ec;
    fs::remove_all(path_, ec);
  }
  Scratch(const Scratch&) = delete;
  Scratch& operator=(const Scratch&) = delete;
  const fs::path& path() const { return path_; }
  void touch(const std::string& name) const {
    fs::create_directories((path_ / name).parent_path());
    std::ofstream(path_ / name) << "x";
  }

 private:
  fs::path path_;
};

class Confinement : public ::testing::Test {
 protected:
  Confinement() {
    fs::create_directories(root.path() / "models");
    root.touch("models/ref.png");
    outside.touch("secret.png");
  }
  // The refusal message, or "" when the path was accepted.
  std::string refusal(const std::string& written, const fs::path& base) const {
    const auto r = confinedPath(written, base, root.path());
    if (const auto* why = std::get_if<std::string>(&r)) return *why;
    return "";
  }
  std::string refusal(const std::string& written) const { return refusal(written, root.path()); }
  fs::path accepted(const std::string& written) const {
    const auto r = confinedPath(written, root.path(), root.path());
    const auto* p = std::get_if<fs::path>(&r);
    return p ? *p : fs::path{};
  }

  Scratch root;
  Scratch outside;
};

TEST_F(Confinement, PlainRelativePathsResolveInsideTheFolder) {
  EXPECT_EQ(accepted("models/ref.png"), root.path() / "models" / "ref.png");
  EXPECT_EQ(accepted("models/./../models/ref.png"), root.path() / "models" / "ref.png");
  EXPECT_EQ(accepted("models/not_trained_yet.shape"),
            root.path() / "models" / "not_trained_yet.shape");
}

TEST_F(Confinement, DotDotLeavingTheFolderIsRefused) {
  const std::string escape = fs::relative(outside.path() / "secret.png", root.path()).string();
  ASSERT_TRUE(escape.starts_with(".."));
  EXPECT_NE(refusal(escape).find("leaves the recipes folder"), std::string::npos);
  EXPECT_NE(refusal("..").find("leaves the recipes folder"), std::string::npos);
  EXPECT_NE(refusal("models/../../x.png").find("leaves the recipes folder"), std::string::npos);
  // From a recipe in a subfolder, `..` may go up to the root but not past it.
  EXPECT_EQ(refusal("../models/ref.png", root.path() / "models"), "");
  EXPECT_NE(refusal("../../x.png", root.path() / "models").find("leaves the recipes folder"),
            std::string::npos);
}

TEST_F(Confinement, AbsolutePathsAreRefusedEvenInsideTheFolder) {
  EXPECT_NE(refusal("/etc/passwd").find("is absolute"), std::string::npos);
  EXPECT_NE(refusal((root.path() / "models/ref.png").string()).find("is absolute"),
            std::string::npos);
  EXPECT_NE(refusal("//server/share/x.png").find("is absolute"), std::string::npos);
}

TEST_F(Confinement, SymbolicLinksOutOfTheFolderAreRefused) {
  fs::create_symlink(outside.path() / "secret.png", root.path() / "link.png");
  fs::create_directory_symlink(outside.path(), root.path() / "linkdir");
  EXPECT_NE(refusal("link.png").find("through a symbolic link"), std::string::npos);
  EXPECT_NE(refusal("linkdir/secret.png").find("through a symbolic link"), std::string::npos);
  // A relative link that climbs out.
  fs::create_symlink(fs::relative(outside.path() / "secret.png", root.path() / "models"),
                     root.path() / "models" / "relative_link.png");
  EXPECT_NE(refusal("models/relative_link.png").find("through a symbolic link"), std::string::npos);
}

TEST_F(Confinement, DanglingSymbolicLinksOutOfTheFolderAreRefused) {
  // Targets that do not exist yet: a model file about to be trained, a folder about to be made.
  fs::create_symlink(outside.path() / "model.shape", root.path() / "models" / "evil.shape");
  fs::create_directory_symlink(outside.path() / "nowhere", root.path() / "newdir");
  EXPECT_NE(refusal("models/evil.shape").find("through a symbolic link"), std::string::npos);
  EXPECT_NE(refusal("newdir/model.shape").find("through a symbolic link"), std::string::npos);
  // A chain: inside link -> inside dangling link -> outside.
  fs::create_symlink("evil.shape", root.path() / "models" / "chain.shape");
  EXPECT_NE(refusal("models/chain.shape").find("through a symbolic link"), std::string::npos);
}

TEST_F(Confinement, SymbolicLinksThatStayInsideAreFine) {
  fs::create_symlink("ref.png", root.path() / "models" / "current.png");
  fs::create_symlink("v2.shape", root.path() / "models" / "current.shape");  // not trained yet
  EXPECT_EQ(refusal("models/current.png"), "");
  EXPECT_EQ(refusal("models/current.shape"), "");
}

TEST_F(Confinement, LinkLoopsAreRefusedNotFollowedForever) {
  fs::create_symlink("b.png", root.path() / "a.png");
  fs::create_symlink("a.png", root.path() / "b.png");
  EXPECT_NE(refusal("a.png"), "");
}

}  // namespace
