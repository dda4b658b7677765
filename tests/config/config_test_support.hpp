#pragma once
// Shared by the config tests: a scratch folder that is removed afterwards, and a matcher for
// "a diagnostic at line L, column C whose message contains S".

#include <filesystem>
#include <string>

#include <gtest/gtest.h>

#include "config/diagnostic.hpp"
#include "config/step_kind.hpp"

namespace facet::config::test {

// facet's step kinds, as facetd and `facet` read recipes with them.
const StepKindRegistry& facetSteps();

class ScratchFolder {
 public:
  ScratchFolder();
  ~ScratchFolder();
  ScratchFolder(const ScratchFolder&) = delete;
  ScratchFolder& operator=(const ScratchFolder&) = delete;

  [[nodiscard]] const std::filesystem::path& path() const { return path_; }
  // Writes `text` to path()/name (creating folders) and returns the full path.
  std::filesystem::path write(const std::string& name, const std::string& text) const;
  // Writes a small grey 8-bit PNG with a bright rectangle (something to train on).
  std::filesystem::path writeImage(const std::string& name, int width = 64, int height = 48) const;

 private:
  std::filesystem::path path_;
};

// Succeeds when `diagnostics` has an error (or warning, with `warning`) at exactly
// line:column of a file named `fileName` whose message contains `fragment`.
testing::AssertionResult hasDiagnostic(const Diagnostics& diagnostics, int line, int column,
                                       const std::string& fragment, bool warning = false);

}  // namespace facet::config::test
