#pragma once
// Each subcommand registers itself on the CLI11 app; its callback throws InputError/OutputError on failure.
#include <CLI/CLI.hpp>
#include <stdexcept>

#include "core/error.h"  // the exit codes (one table for all commands)

namespace kf {

// Thrown by a subcommand that is not available yet; exits with kExitNotReady.
struct NotReady : std::runtime_error {
  using std::runtime_error::runtime_error;
};

// Thrown by `compare` when some frame fails its thresholds (reports are written); exits with kExitDifferent.
struct FramesDiffer : std::runtime_error {
  using std::runtime_error::runtime_error;
};

void add_simulate_command(CLI::App& app);
void add_optimize_command(CLI::App& app);
void add_run_command(CLI::App& app);
void add_render_command(CLI::App& app);
void add_gradcheck_command(CLI::App& app);
void add_figure_command(CLI::App& app);
void add_bench_command(CLI::App& app);
void add_clip_command(CLI::App& app);
void add_export_command(CLI::App& app);
void add_compare_command(CLI::App& app);
void add_farm_command(CLI::App& app);
void add_inspect_command(CLI::App& app);
void add_schema_command(CLI::App& app);

}  // namespace kf
