// What a recipe's author is told when a recipe is wrong: the YAML syntax error at its own line
// and column, one error per cause, a file that is no model called that.
#include <gtest/gtest.h>

#include "config/recipe_loader.hpp"
#include "config/recipe_training.hpp"
#include "config/training_record.hpp"
#include "tests/config/config_test_support.hpp"

namespace facet::config::test {
namespace {

class RecipeErrorWording : public testing::Test {
 protected:
  void SetUp() override { scratch.writeImage("ref.png"); }

  RecipeLoadResult load(const std::string& text, RecipeLoadOptions options = {}) {
    const auto file = scratch.write("test.recipe.yaml", text);
    if (!options.root) options.root = scratch.path();
    return loadRecipe(file, facetSteps(), options);
  }

  ScratchFolder scratch;
};

// yaml-cpp takes a quote that never closes as text running to the end of the file (and then
// only "missing key 'steps'" was reported, at 1:1).
TEST_F(RecipeErrorWording, UnterminatedQuoteIsASyntaxErrorAtTheQuote) {
  const auto r = load(R"(schema_version: 1
id: 7
name: "broken
steps:
  - id: part
    kind: align
    method: registration
    reference: ref.png
)");
  EXPECT_FALSE(r.recipe.has_value());
  EXPECT_TRUE(hasDiagnostic(r.diagnostics, 3, 7, "the closing \" is missing"))
      << r.diagnostics.text();
  EXPECT_EQ(r.diagnostics.errorCount(), 1u) << r.diagnostics.text();
  EXPECT_EQ(r.diagnostics.text().find("missing required key"), std::string::npos)
      << r.diagnostics.text();
}

// The quote closes, but only at the next value's opening quote, lines later.
TEST_F(RecipeErrorWording, QuoteClosedOnlyByALaterValueIsASyntaxError) {
  const auto r = load(R"(schema_version: 1
id: 7
name: 'broken
description: 'a recipe'
steps:
  - id: part
    kind: align
    method: registration
    reference: ref.png
)");
  EXPECT_FALSE(r.recipe.has_value());
  EXPECT_TRUE(hasDiagnostic(r.diagnostics, 3, 7, "runs on over the key on line 4"))
      << r.diagnostics.text();
}

// Quoted text that legitimately spans lines, and quotes inside quotes, stay valid.
TEST_F(RecipeErrorWording, ProperlyQuotedTextIsUntouched) {
  const auto r = load(R"(schema_version: 1
id: 7
name: "it's \"quoted\""
description: 'two
  lines, one ''quote'''
steps:
  - id: part
    kind: align
    method: registration
    reference: ref.png
)");
  ASSERT_TRUE(r.recipe.has_value()) << r.diagnostics.text();
  EXPECT_EQ(r.recipe->name, "it's \"quoted\"");
  EXPECT_EQ(r.recipe->description, "two lines, one 'quote'");
}

// A misspelt kind is one error: the steps that use that step do not add "comes later".
TEST_F(RecipeErrorWording, UnknownKindDoesNotCascade) {
  const auto r = load(R"(schema_version: 1
id: 7
name: Test
steps:
  - id: part
    kind: align
    method: registration
    reference: ref.png
  - id: corner_bore
    kind: circel
    relative_to: part
    centre: [30, 20]
    nominal_diameter: 1.0
    search_width: 0.3
  - id: spacing
    kind: distance
    measure: centre_to_centre
    from: corner_bore
    to: part
)");
  EXPECT_FALSE(r.recipe.has_value());
  EXPECT_TRUE(hasDiagnostic(r.diagnostics, 10, 11, "circel")) << r.diagnostics.text();
  EXPECT_EQ(r.diagnostics.errorCount(), 1u) << r.diagnostics.text();
  EXPECT_EQ(r.diagnostics.text().find("comes later"), std::string::npos) << r.diagnostics.text();
}

// A text file where the model should be: "cannot be loaded ... not a facet shape model file",
// not "stale: changed after training".
TEST_F(RecipeErrorWording, TextFileAsModelIsNotAModel) {
  scratch.writeImage("label.png", 96, 64);
  const std::string text = R"(schema_version: 1
id: 7
name: Test
steps:
  - id: part
    kind: align
    method: registration
    reference: ref.png
  - id: label
    kind: shape
    relative_to: part
    template: label.png
    model: models/label.shape
)";
  RecipeLoadOptions training;
  training.requireTrainedModels = false;
  auto r = load(text, training);
  ASSERT_TRUE(r.recipe.has_value()) << r.diagnostics.text();
  ASSERT_EQ(trainRecipe(*r.recipe).size(), 1u);
  scratch.write("models/label.shape", "a note somebody saved under the model's name\n");
  r = load(text);
  EXPECT_FALSE(r.recipe.has_value());
  EXPECT_TRUE(hasDiagnostic(r.diagnostics, 13, 12, "not a facet shape model file"))
      << r.diagnostics.text();
  EXPECT_EQ(r.diagnostics.text().find("stale"), std::string::npos) << r.diagnostics.text();
}

// An empty file name is one error, said as such: it was also "not text" and, a second error for
// the same key, "file '' cannot be read as an image" (and OpenCV warned on the daemon's log).
TEST_F(RecipeErrorWording, EmptyFileNameIsOneErrorSayingSo) {
  for (const char* method : {"shape", "registration"}) {
    const auto r = load(std::string(R"(schema_version: 1
id: 7
name: Test
steps:
  - id: part
    kind: align
    method: )") + method +
                        R"(
    reference: ""
    model: models/part.shape
)");
    EXPECT_FALSE(r.recipe.has_value()) << method;
    EXPECT_TRUE(hasDiagnostic(r.diagnostics, 8, 16, "'reference' is empty: name a file"))
        << method << "\n"
        << r.diagnostics.text();
    EXPECT_EQ(r.diagnostics.errorCount(), 1u) << method << "\n" << r.diagnostics.text();
  }
}

// A file that is not there: one error, at the key; the model is not looked for.
TEST_F(RecipeErrorWording, MissingTemplateIsOneError) {
  const auto r = load(R"(schema_version: 1
id: 7
name: Test
steps:
  - id: part
    kind: align
    method: shape
    reference: nothere.png
    model: models/part.shape
)");
  EXPECT_FALSE(r.recipe.has_value());
  EXPECT_TRUE(hasDiagnostic(r.diagnostics, 8, 16, "does not exist")) << r.diagnostics.text();
  EXPECT_EQ(r.diagnostics.errorCount(), 1u) << r.diagnostics.text();
}

}  // namespace
}  // namespace facet::config::test
