// Coordinator throughput (issue 5 acceptance 8, first part): a run of no-op jobs served to worker threads in this
// process over TCP on 127.0.0.1 (the same DEALER loop as `drapegen worker`). Every job is dispatched, answered,
// recorded and committed to the manifest (WAL, synchronous=FULL), so the rate is dispatch + record + commit.
// Usage: drapegen_service_bench [--jobs N] [--workers K] [--dir DIR]
#include <atomic>
#include <chrono>
#include <cstdio>
#include <filesystem>
#include <fmt/format.h>
#include <string>
#include <thread>
#include <vector>

#include <CLI/CLI.hpp>

#include "drapegen/coordinator/coordinator.hpp"
#include "drapegen/coordinator/logging.hpp"
#include "drapegen/storage/manifest_reader.hpp"
#include "drapegen/worker/worker.hpp"

int main(int argc, char** argv) {
  CLI::App app{"Coordinator throughput with no-op jobs"};
  int jobs = 20000, workers = 4;
  std::string dir = (std::filesystem::temp_directory_path() / "drapegen_service_bench").string();
  app.add_option("--jobs", jobs, "No-op jobs (rounded up to a multiple of 8)")->capture_default_str();
  app.add_option("--workers", workers, "Worker threads")->capture_default_str();
  app.add_option("--dir", dir, "Output directory (removed first)")->capture_default_str();
  CLI11_PARSE(app, argc, argv);

  std::filesystem::remove_all(dir);
  const int samples = (jobs + 7) / 8;
  const std::string config = fmt::format(
      "seed = 1\nsamples = {}\nstates_per_sample = 8\noutput = \"{}\"\n[network]\nbind = \"tcp://127.0.0.1:*\"\n"
      "[progress]\ninterval_s = 1000\n[testing]\nmode = \"noop\"\n",
      samples, dir);
  drapegen::coordinator::logger()->set_level(spdlog::level::warn);
  drapegen::coordinator::CoordinatorOptions options;
  options.progress = drapegen::coordinator::CoordinatorOptions::Progress::kOff;
  options.shutdown_linger_ms = 0;
  const auto plan_start = std::chrono::steady_clock::now();
  auto coordinator = drapegen::coordinator::Coordinator::create(config, "bench", options);
  if (!coordinator) {
    std::fprintf(stderr, "error: %s\n", coordinator.error().message.c_str());
    return 1;
  }
  const double plan_seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - plan_start).count();
  std::atomic<bool> stop_workers{false};
  std::vector<std::thread> threads;
  for (int k = 0; k < workers; ++k) {
    threads.emplace_back([&, k] {
      drapegen::worker::WorkerOptions o;
      o.endpoint = (*coordinator)->endpoint();
      o.name = fmt::format("bench-{}", k);
      (void)drapegen::worker::run_worker(o, stop_workers);
    });
  }
  std::atomic<bool> stop{false};
  const auto start = std::chrono::steady_clock::now();
  const auto summary = (*coordinator)->run(stop);
  const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  stop_workers = true;
  for (auto& t : threads) t.join();

  // The same figure from the manifest's own timestamps: first lease to last recorded result.
  auto reader = drapegen::storage::ManifestReader::open((*coordinator)->manifest_path());
  double first = 1e300, last = 0.0;
  std::size_t done = 0;
  if (reader) {
    for (const auto& j : reader->jobs().value()) {
      if (j.state != drapegen::storage::JobState::kDone) continue;
      ++done;
      first = std::min(first, j.started_at);
      last = std::max(last, j.finished_at);
    }
  }
  std::printf("jobs %lld, workers %d: planned in %.2f s; run %.2f s = %.0f jobs/s (dispatch + record + commit)\n",
              static_cast<long long>(summary.total), workers, plan_seconds, seconds,
              static_cast<double>(summary.done) / seconds);
  std::printf("manifest: %zu done, first lease to last result %.2f s = %.0f jobs/s\n", done, last - first,
              static_cast<double>(done) / (last - first));
  return summary.done == summary.total ? 0 : 1;
}
