// Command-line parsing shared by the programs (CLI11, header-only; link CLI11::CLI11).
// docs/programs.md: --help exits 0, bad usage exits 2 with a message that names the flag.
#pragma once

#include <cstdio>
#include <string>

#include <CLI/CLI.hpp>

#include "core/error.h"
#include "core/paths.h"

namespace eik {

// Parses argv into `app`. Returns false when --help was asked for (the help is printed and the
// program should exit 0); throws InputError for bad usage.
inline bool parseCommandLine(CLI::App& app, int argc, char** argv) {
  try {
    app.parse(argc, argv);
  } catch (const CLI::CallForHelp&) {
    std::printf("%s", app.help().c_str());
    return false;
  } catch (const CLI::ParseError& e) {
    throw InputError(std::string("command line: ") + e.what() + " (see " + app.get_name() + " --help)");
  }
  return true;
}

// --allow-outside-paths, which every program has (docs/programs.md, "Paths inside files").
inline void addOutsidePathsFlag(CLI::App& app) {
  app.add_flag_callback("--allow-outside-paths", [] { allowPathsOutsideFolder(true); },
                        "follow paths inside the input files (a NRRD's data file, a manifest's fields, a scene's "
                        "volumes and environment, glTF URIs) that leave the folder of the file naming them");
}

}  // namespace eik
