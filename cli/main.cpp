// drapegen: synthetic drape data for bending-parameter estimation. One program, one subcommand per job.
#include <iostream>
#include <map>
#include <new>
#include <string>

#include "commands.hpp"
#include "parse.hpp"
#include "drapegen/build_id.hpp"
#include "drapegen/sim/blas_kernels.hpp"

int main(int argc, char** argv) {
  // Before anything else: on CPUs Debian's OpenBLAS does not know, start again on the kernels the CPU supports.
  drapegen::sim::relaunch_with_blas_kernels(argv);
  CLI::App app{"drapegen - cloth drape simulation for learning fabric bending stiffness"};
  app.require_subcommand(1);
  app.set_version_flag("--version", "drapegen " DRAPEGEN_BUILD_ID);
  std::map<CLI::App*, drapegen::cli::Runner> runners;
  auto add = [&](const char* name, const char* description, auto factory) {
    CLI::App* sub = app.add_subcommand(name, description);
    runners[sub] = factory(*sub);
  };
  add("simulate", "Simulate one drape on the drape tester and print its summary", drapegen::cli::add_simulate_command);
  add("cantilever", "Simulate a clamped strip hanging under its own weight (physical validation)",
      drapegen::cli::add_cantilever_command);
  add("render", "Render a drape to noisy multi-view depth images (OpenEXR) as the drape tester sees it",
      drapegen::cli::add_render_command);
  add("sample", "Sample parameter vectors from the VAE subspace and their initial states, or report coverage",
      drapegen::cli::add_sample_command);
  add("reality", "Simulate and render a capture with effects the baseline model lacks, truth in a separate file",
      drapegen::cli::add_reality_command);
  add("diagnose", "Diagnose a capture's sim-to-real gap: fit, floors, localisation, attribution",
      drapegen::cli::add_diagnose_command);
  add("run", "Coordinate a generation run: plan it, serve its jobs to workers, record results (or --resume one)",
      drapegen::cli::add_run_command);
  add("worker", "Compute jobs (simulate + render) for a coordinator", drapegen::cli::add_worker_command);
  add("local", "Run a coordinator and N workers on this machine (default: a small embedded run), then print stats",
      drapegen::cli::add_local_command);
  add("stats", "Summarise a run's manifest (counts, failures, throughput, distributions, storage)",
      drapegen::cli::add_stats_command);
  add("keygen", "Make a CurveZMQ key pair (coordinator or worker) for runs on non-loopback addresses",
      drapegen::cli::add_keygen_command);
  // Integers in base 10 everywhere: CLI11 would read --seed 010 as octal 8, 0x10 as 16 and 0b11 as 3.
  const CLI::Validator decimal(
      [](std::string& text) {
        if (!drapegen::cli::is_decimal_integer(text)) return "'" + text + "' is not a decimal integer";
        text = drapegen::cli::decimal_integer(text);
        return std::string();
      },
      "");
  for (CLI::App* sub : app.get_subcommands({})) {
    for (CLI::Option* option : sub->get_options()) {
      const std::string type = option->get_type_name();
      if (type.rfind("INT", 0) == 0 || type.rfind("UINT", 0) == 0) option->transform(decimal);
    }
  }
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    if (e.get_exit_code() == 0) return app.exit(e);  // --help, --version
    // Like every other bad input: one line on stderr, exit code 1.
    std::string message = e.what();
    for (char& c : message) c = c == '\n' ? ' ' : c;
    std::string where = "drapegen";
    for (const auto& [sub, run] : runners) {
      if (sub->parsed()) where += " " + sub->get_name();
    }
    if (where == "drapegen" && argc > 1 && argv[1][0] != '-') {
      // CLI11 calls a mistyped command a missing one ("A subcommand is required"): name it and the known ones.
      message = "unknown command '" + std::string(argv[1]) + "'; the commands:";
      for (const CLI::App* sub : app.get_subcommands({})) message += " " + sub->get_name();
    }
    std::cerr << where << ": error: " << message << " (see --help)\n";
    return drapegen::cli::kExitUsage;
  }
  for (const auto& [sub, run] : runners) {
    if (!sub->parsed()) continue;
    try {
      const int code = run();
      // What a command printed (a summary, --json) is an output too: lost to a full disk, exit 3 (unless the command
      // failed already: its own code stands).
      if (!std::cout.flush()) {
        std::cerr << "drapegen " << sub->get_name() << ": error: cannot write the standard output\n";
        return code == drapegen::cli::kExitOk ? drapegen::cli::kExitIo : code;
      }
      return code;
    } catch (const std::bad_alloc&) {
      // The commands that take a mesh resolution can be told how to need less.
      const bool meshed = sub->get_option_no_throw("--resolution") != nullptr;
      std::cerr << "drapegen " << sub->get_name() << ": error: out of memory"
                << (meshed ? " (try a smaller --resolution)" : "") << "\n";
    } catch (const std::exception& e) {
      std::cerr << "drapegen " << sub->get_name() << ": error: " << e.what() << "\n";
    }
    return drapegen::cli::kExitUsage;
  }
  return drapegen::cli::kExitUsage;
}
