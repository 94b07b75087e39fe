// drapegen run: the coordinator of a generation run (docs/SERVICE.md).
#include <fmt/format.h>

#include <iostream>
#include <memory>

#include "commands.hpp"
#include "drapegen/coordinator/coordinator.hpp"
#include "drapegen/storage/read_file.hpp"
#include "failure.hpp"
#include "signals.hpp"

namespace drapegen::cli {
namespace {

struct RunOptions {
  std::string config;
  std::string resume;
  std::string bind;
  std::string progress = "auto";
  std::string server_key;
  std::string authorized_keys;
  std::string endpoint_file;
  bool retry_failed = false;
};

const Failure fail{"run"};

coordinator::CoordinatorOptions::Progress parse_progress(const std::string& p) {
  using P = coordinator::CoordinatorOptions::Progress;
  if (p == "terminal") return P::kTerminal;
  if (p == "log") return P::kLog;
  if (p == "off") return P::kOff;
  return P::kAuto;
}

}  // namespace

int report_run(const coordinator::RunSummary& s, const std::string& manifest, const char* sub) {
  switch (s.outcome) {
    case coordinator::RunOutcome::kComplete:
      std::cout << fmt::format("run complete: {} done, {} failed of {} jobs ({} recorded in {:.1f} s); manifest {}\n",
                               s.done, s.failed, s.total, s.recorded_this_session, s.seconds, manifest);
      return kExitOk;
    case coordinator::RunOutcome::kStopped:
      std::cerr << fmt::format("drapegen {0}: stopped with {1} done, {2} failed of {3} jobs; continue with: drapegen "
                               "{0} --resume {4}\n",
                               sub, s.done, s.failed, s.total, manifest);
      return kExitStopped;
    case coordinator::RunOutcome::kStorageError:
      std::cerr << fmt::format("drapegen {0}: error: {1} (stopped with {2} of {3} jobs recorded; fix it, then: "
                               "drapegen {0} --resume {4})\n",
                               sub, s.message, s.done + s.failed, s.total, manifest);
      return kExitIo;
  }
  return kExitUsage;
}

Runner add_run_command(CLI::App& app) {
  auto o = std::make_shared<RunOptions>();
  auto* config = app.add_option("--config", o->config, "Run configuration (TOML; keys in docs/SERVICE.md)");
  auto* resume = app.add_option("--resume", o->resume, "Continue the run of this manifest (OUTPUT/manifest.sqlite)");
  config->excludes(resume);
  app.add_flag("--retry-failed", o->retry_failed,
               "With --resume: failed jobs are pending again, each with retry.max_attempts more attempts (their "
               "failures stay recorded)")
      ->needs(resume);
  app.add_option("--bind", o->bind, "Bind this endpoint instead of the configured/recorded one, e.g. tcp://127.0.0.1:*")
      ->check(kEndpoint);
  app.add_option("--progress", o->progress,
                 "Progress display: auto (terminal line if stderr is a TTY), terminal, log, off")
      ->check(CLI::IsMember({"auto", "terminal", "log", "off"}))
      ->capture_default_str();
  app.add_option("--server-key", o->server_key, "CurveZMQ secret key file (overrides [security] server_secret_key)");
  app.add_option("--authorized-keys", o->authorized_keys,
                 "Worker public keys file (overrides [security] authorized_keys)");
  app.add_option("--endpoint-file", o->endpoint_file, "Also write the bound endpoint to this file");
  return [o] {
    if (o->config.empty() == o->resume.empty()) return fail("give --config RUN.toml or --resume MANIFEST");
    const auto& stop = install_stop_signals();
    coordinator::CoordinatorOptions options;
    options.bind_override = o->bind;
    options.progress = parse_progress(o->progress);
    options.server_secret_key = o->server_key;
    options.authorized_keys = o->authorized_keys;
    options.endpoint_file = o->endpoint_file;
    options.retry_failed = o->retry_failed;
    sim::Expected<std::unique_ptr<coordinator::Coordinator>> c = sim::Error{""};
    if (!o->config.empty()) {
      auto text = storage::read_file(o->config);
      if (!text) return fail(text.error().message);
      c = coordinator::Coordinator::create(*text, o->config, options);
    } else {
      c = coordinator::Coordinator::resume(o->resume, options);
    }
    if (!c) return fail(c.error());
    const auto summary = (*c)->run(stop);
    return report_run(summary, (*c)->manifest_path(), "run");
  };
}

}  // namespace drapegen::cli
