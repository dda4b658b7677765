// facet: the command-line tool. Runs facet's algorithms one image at a time, trains models,
// checks recipes and replays folders. See command_line.hpp for the output conventions.
// runFacet() is the whole program for a set of step kinds; facet_main.cpp runs it with facet's
// own (a test adds a kind of its own).
#include <iostream>

#include <opencv2/core/utils/logger.hpp>

#include "config/closest_name.hpp"
#include "service/cli/command_line.hpp"

namespace facet::cli {

void printJson(const nlohmann::json& object) {
  std::cout << object.dump() << std::endl;
}

namespace {

// The names of `app`'s subcommands, in the order they were added.
std::vector<std::string> commandNames(CLI::App& app) {
  std::vector<std::string> names;
  for (const CLI::App* sub : app.get_subcommands({})) names.push_back(sub->get_name());
  return names;
}

std::string joined(const std::vector<std::string>& names) {
  std::string text;
  for (const auto& name : names) text += (text.empty() ? "" : ", ") + name;
  return text;
}

// A command line that names no command, or one that does not exist, at any level ("facet",
// "facet bogus", "facet recipe chek"): CLI11 would only say "A subcommand is required". Returns
// the message naming what is missing or unknown, with the nearest command when it is a typo.
std::optional<std::string> commandProblem(CLI::App& app, int argc, char** argv) {
  CLI::App* current = &app;
  std::string path = "facet";
  for (int i = 1;; ++i) {
    const std::vector<std::string> names = commandNames(*current);
    if (names.empty() || current->get_require_subcommand_min() == 0) return std::nullopt;
    if (i >= argc)
      return path + ": give a command: " + joined(names) + " ('" + path + " --help' says more)";
    const std::string word = argv[i];
    if (word.starts_with("-")) return std::nullopt;  // --help, or an option CLI11 will judge
    CLI::App* sub = nullptr;
    for (CLI::App* candidate : current->get_subcommands({}))
      if (candidate->check_name(word)) sub = candidate;
    if (sub == nullptr) {
      std::string message = path + ": unknown command '" + word + "'";
      if (const auto near = config::closestName(word, names))
        message += "; did you mean '" + *near + "'?";
      return message + " (commands: " + joined(names) + ")";
    }
    current = sub;
    path += " " + word;
  }
}

// The subcommand chain the user named, for pointing at the right --help.
std::string commandPath(CLI::App& app) {
  std::string path = app.get_name();
  for (CLI::App* current = &app;;) {
    const auto used = current->get_subcommands();
    if (used.empty()) return path;
    current = used.front();
    path += " " + current->get_name();
  }
}

}  // namespace

int runFacet(int argc, char** argv, const config::StepKindRegistry& kinds) {
  // Decoders report through our own messages (readGreyImage); OpenCV's log would only repeat
  // them as "[ WARN:0@0.037] global ... findDecoder imread_(...)" on stderr.
  cv::utils::logging::setLogLevel(cv::utils::logging::LOG_LEVEL_SILENT);
  CLI::App app{"facet: machine-vision inspection tool", "facet"};
  app.require_subcommand(1);
  addVersionCommand(app);
  addPlcSimCommand(app);
  addCircleCommand(app);
  addCaliperCommand(app);
  addLineCommand(app);
  addBlobCommand(app);
  addScanMatchCommand(app);
  addResultsCommand(app);
  addEdgesCommand(app);
  addModelCommand(app);
  addMatchCommand(app);
  addRegisterCommand(app);
  addRecipeCommand(app, kinds);
  addReplayCommand(app, kinds);
  addCalibrateCommand(app);
  addValidateCommand(app, kinds);

  if (const auto problem = commandProblem(app, argc, argv)) {
    std::cerr << *problem << "\n";
    return 1;
  }
  bool jsonWanted = false;
  for (int i = 1; i < argc; ++i) jsonWanted = jsonWanted || std::string(argv[i]) == "--json";
  try {
    app.parse(argc, argv);
  } catch (const CLI::RuntimeError& e) {
    return e.get_exit_code();  // a command's own exit code (validate: 3 on a mismatch)
  } catch (const CLI::ParseError& e) {
    if (e.get_exit_code() == 0) return app.exit(e);  // --help
    // A wrong argument is bad input (exit 1), as the README promises; CLI11's own codes
    // (104-108) would tell a script nothing it can rely on.
    std::cerr << "facet: " << e.what() << " ('" << commandPath(app)
              << " --help' lists the options)\n";
    return 1;
  } catch (const MeasurementFailure& e) {
    if (jsonWanted)
      printJson({{"error", {{"cause", e.cause}, {"message", e.what()}}}});
    else
      std::cerr << "facet: " << e.cause << ": " << e.what() << "\n";
    return 2;
  } catch (const std::exception& e) {
    std::cerr << "facet: " << e.what() << "\n";
    return 1;
  }
  return 0;
}

}  // namespace facet::cli
