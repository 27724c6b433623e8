#pragma once
// Each sub-command of the hiveslam program registers itself on the top-level CLI11 app.
// Callbacks report bad input by throwing hiveslam::InputError; main prints it on one line.
#include <CLI/CLI.hpp>

namespace hiveslam::apps {

void addSynthCommand(CLI::App& app);
void addEvalCommand(CLI::App& app);
void addInfoCommand(CLI::App& app);
void addDemoCommand(CLI::App& app);
void addRunCommand(CLI::App& app);
void addVocabCommand(CLI::App& app);
void addNodeCommand(CLI::App& app);
void addClusterCommand(CLI::App& app);
void addBenchCommand(CLI::App& app);
void addPlayCommand(CLI::App& app);
void addViewCommand(CLI::App& app);
void addTopicsCommand(CLI::App& app);
void addKeysCommand(CLI::App& app);

}  // namespace hiveslam::apps
