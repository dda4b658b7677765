#include <iostream>

#include "service/cli/command_line.hpp"

namespace facet::cli {

void addVersionCommand(CLI::App& app) {
  auto* cmd = app.add_subcommand("version", "Print the version of facet");
  auto json = std::make_shared<bool>(false);
  cmd->add_flag("--json", *json, "Print JSON");
  cmd->callback([json] {
    if (*json)
      printJson({{"version", FACET_VERSION}});
    else
      std::cout << "facet " << FACET_VERSION << "\n";
  });
}

}  // namespace facet::cli
