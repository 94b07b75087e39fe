#pragma once
// The subcommands of the drapegen program. Each registers its options on the app and returns a runner that
// returns the process exit code.

#include <CLI/CLI.hpp>
#include <functional>

namespace drapegen::cli {

using Runner = std::function<int()>;

/// Exit codes shared by all subcommands.
enum ExitCode : int {
  kExitOk = 0,
  kExitUsage = 1,        // bad input: one line on stderr says why
  kExitNotConverged = 2, // the computation ran but did not reach its goal (the outcome says why)
  kExitIo = 3,           // an output could not be written
  kExitStopped = 4,      // a run stopped by SIGINT/SIGTERM before it completed (continue with --resume)
  kExitRunStopped = 5,   // drapegen worker: the coordinator stopped the run before its end (a resume wants workers)
};

/// What is wrong with a ZeroMQ endpoint ("" if nothing), as the configuration's network.bind is checked.
[[nodiscard]] std::string endpoint_problem(const std::string& endpoint);

/// A ZeroMQ endpoint option, checked as the configuration's network.bind.
inline const CLI::Validator kEndpoint([](const std::string& value) { return endpoint_problem(value); }, "ENDPOINT");

/// A 64-bit seed option: digits only, at most 2^64 - 1 (CLI11 alone wraps "-1" round and clamps larger values).
inline const CLI::Validator kSeed(
    [](const std::string& value) -> std::string {
      const std::string max = "18446744073709551615";
      const bool digits = !value.empty() && value.find_first_not_of("0123456789") == std::string::npos;
      if (digits && (value.size() < max.size() || (value.size() == max.size() && value <= max))) return {};
      return "'" + value + "' is not a seed (an integer 0 .. " + max + ")";
    },
    "SEED");

Runner add_simulate_command(CLI::App& app);
Runner add_cantilever_command(CLI::App& app);
Runner add_render_command(CLI::App& app);
Runner add_sample_command(CLI::App& app);
Runner add_reality_command(CLI::App& app);
Runner add_diagnose_command(CLI::App& app);
Runner add_run_command(CLI::App& app);
Runner add_worker_command(CLI::App& app);
Runner add_local_command(CLI::App& app);
Runner add_stats_command(CLI::App& app);
Runner add_keygen_command(CLI::App& app);

}  // namespace drapegen::cli
