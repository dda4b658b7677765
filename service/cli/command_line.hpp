#pragma once
// Shared conventions of the `facet` command-line tool's subcommands.
//
// - A measuring command takes --json and then prints exactly one JSON object on stdout.
// - Bad input (unreadable file, bad value) throws InputError: main prints "facet: <message>" on
//   stderr and exits with 1.
// - A measurement that ran but found nothing usable throws MeasurementFailure: with --json,
//   main prints {"error": {"cause": ..., "message": ...}} on stdout; the exit code is 2.

#include <stdexcept>
#include <string>

#include <CLI/CLI.hpp>
#include <nlohmann/json.hpp>
#include <opencv2/core/mat.hpp>

#include "config/step_kind.hpp"

namespace facet::cli {

struct InputError : std::runtime_error {
  using std::runtime_error::runtime_error;
};

struct MeasurementFailure : std::runtime_error {
  MeasurementFailure(std::string cause, const std::string& message)
      : std::runtime_error(message), cause(std::move(cause)) {}
  std::string cause;  // machine-readable, snake_case
};

// Prints one JSON object on stdout, on one line.
void printJson(const nlohmann::json& object);

// The image file at `path` as one grey channel, 8 or 16 bits deep (colour is converted to grey).
// Throws InputError naming the file: "no such file", unreadable, not an image, corrupt.
cv::Mat readGreyImage(const std::string& path);

// Every subcommand is added by a function of this shape, one file per subcommand.
// The subcommand's callback does the work; `json` tells whether --json was given anywhere.
void addVersionCommand(CLI::App& app);
void addPlcSimCommand(CLI::App& app);
void addCircleCommand(CLI::App& app);
void addCaliperCommand(CLI::App& app);
void addLineCommand(CLI::App& app);
void addBlobCommand(CLI::App& app);
void addScanMatchCommand(CLI::App& app);
void addResultsCommand(CLI::App& app);
void addEdgesCommand(CLI::App& app);
void addModelCommand(CLI::App& app);
void addMatchCommand(CLI::App& app);
void addRegisterCommand(CLI::App& app);
void addRecipeCommand(CLI::App& app, const config::StepKindRegistry& kinds);
// The whole program (main.cpp), for the step kinds its recipes may use.
int runFacet(int argc, char** argv, const config::StepKindRegistry& kinds);
void addReplayCommand(CLI::App& app, const config::StepKindRegistry& kinds);
void addCalibrateCommand(CLI::App& app);
void addValidateCommand(CLI::App& app, const config::StepKindRegistry& kinds);

}  // namespace facet::cli
