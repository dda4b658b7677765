// facet: the command-line tool. Runs facet's algorithms one image at a time, trains models,
// checks recipes and replays folders. See command_line.hpp for the output conventions.
// runFacet() is the whole program for a set of step kinds; facet_main.cpp runs it with facet's
// own (a test adds a kind of its own).
#include <iostream>

#include "service/cli/command_line.hpp"

namespace facet::cli {

void printJson(const nlohmann::json& object) {
  std::cout << object.dump() << std::endl;
}

int runFacet(int argc, char** argv, const config::StepKindRegistry& kinds) {
  CLI::App app{"facet: machine-vision inspection tool", "facet"};
  app.require_subcommand(1);
  addVersionCommand(app);
  addPlcSimCommand(app);
  addCircleCommand(app);
  addScanMatchCommand(app);
  addResultsCommand(app);
  addEdgesCommand(app);
  addModelCommand(app);
  addMatchCommand(app);
  addRegisterCommand(app);
  addRecipeCommand(app, kinds);
  addReplayCommand(app, kinds);
  addValidateCommand(app, kinds);

  bool jsonWanted = false;
  for (int i = 1; i < argc; ++i) jsonWanted = jsonWanted || std::string(argv[i]) == "--json";
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    return app.exit(e);
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
