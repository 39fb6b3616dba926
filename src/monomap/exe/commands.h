// The `monomap` binary: one subcommand per file. Each Register* function
// adds its subcommand and sets a callback that throws monomap::Error on
// failure; main() turns errors into messages and exit codes.
#pragma once

#include <CLI/CLI.hpp>

namespace monomap {

void RegisterBuildCommand(CLI::App& app);
void RegisterEvalCommand(CLI::App& app);
void RegisterSimulateCommand(CLI::App& app);
void RegisterDemoCommand(CLI::App& app);
void RegisterRenderCommand(CLI::App& app);
void RegisterLocalizeCommand(CLI::App& app);
void RegisterCalibrateCommand(CLI::App& app);
void RegisterExportCommand(CLI::App& app);
void RegisterImportCommand(CLI::App& app);
void RegisterReportCommand(CLI::App& app);

// --first-frame F and --frames N (the dataset frames a command uses), the
// same for every subcommand that takes them.
void AddFrameRangeOptions(CLI::App* cmd, int* first_frame, int* num_frames);

}  // namespace monomap
