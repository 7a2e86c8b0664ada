// The `ofv` command line: one function per subcommand.
#pragma once

#include "ofv/estimator.h"


#include <CLI/CLI.hpp>

#include <functional>
#include <memory>
#include <string>
#include <vector>

namespace ofv::perception {
struct ObjectSelection;
}  // namespace ofv::perception

namespace ofv::cli {

/// Exit codes shared by every subcommand.
enum ExitCode : int { kOk = 0, kRuntimeFailure = 1, kUsage = 2 };

/// A registered subcommand and its body, run after parsing; returns an ExitCode.
struct Command {
  CLI::App* app = nullptr;
  std::function<int()> run;
};

/// The estimator settings, their defaults and units, for every command's help.
std::string estimator_settings_help();

/// Registers `ofv settings` (every setting: name, type, default, unit, meaning) on the app.
Command add_settings_command(CLI::App& app);

/// Applies `--set name=value` assignments in order.
/// \throws std::invalid_argument naming the assignment when it is malformed or invalid.
void apply_sets(EstimatorParams& params, const std::vector<std::string>& assignments);

/// Registers `ofv estimate` on the app.
Command add_estimate_command(CLI::App& app);

/// Registers `ofv render` (a simulated frame to PNGs) on the app.
Command add_render_command(CLI::App& app);

/// Every setting of the closed loop (`ofv simulate`, `ofv run`), for their help.
std::string episode_settings_help();

/// \throws std::invalid_argument when a `--set name=...` gives setting `name`
/// another value than `flag` (given, with `value`) does: one of them would be
/// ignored. A flag not given (`given` false) leaves --set free.
void refuse_set_against_flag(const std::vector<std::pair<std::string, std::string>>& sets, const std::string& name,
                             const std::string& flag, bool given, const std::string& value);

/// Registers `ofv simulate` (the closed loop in simulation) on the app.
Command add_simulate_command(CLI::App& app);

/// Registers `ofv compare` (settings compared in closed loop) on the app.
Command add_compare_command(CLI::App& app);

/// Registers `ofv run` (the closed loop on a robot and a sensor) on the app.
Command add_run_command(CLI::App& app);

/// Registers `ofv perceive` (perception front end + estimator over a source) on the app.
Command add_perceive_command(CLI::App& app);

/// Adds `--box` and `--rect` (exclusive): the object in the first frame, by
/// a world box or an image rectangle (ofv perceive, ofv run).
void add_selection_options(CLI::App& app, std::string& box, std::string& rect);

/// The selection those options ask for; the front end's default without them.
/// \throws std::invalid_argument naming the option when it is not six (box)
///         or four (rect) comma-separated numbers.
perception::ObjectSelection object_selection(const std::string& box, const std::string& rect);

/// Registers `ofv record` (a simulated episode exported as .oni/TUM/PCD) on the app.
Command add_record_command(CLI::App& app);

}  // namespace ofv::cli
