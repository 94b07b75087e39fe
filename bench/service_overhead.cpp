// End-to-end overhead of the service (issue 5 acceptance 8, second part): `drapegen local --workers W` on a
// configuration, against W plain loops that compute the same jobs (the same library calls as `drapegen simulate`
// + `drapegen render`: simulate, write the PLY, render, encode and write the EXR files) with no coordinator, no
// sockets and no manifest. The loops take jobs from a shared counter (as dynamic as the coordinator's dispatch) and
// run in W processes (one renderer and one solver per process, as the workers).
// Usage: drapegen_service_overhead --config run.toml [--workers 2] [--dir DIR]
#include <chrono>
#include <cstdio>
#include <fcntl.h>
#include <filesystem>
#include <fmt/format.h>
#include <fstream>
#include <spawn.h>
#include <sstream>
#include <string>
#include <sys/file.h>
#include <sys/wait.h>
#include <unistd.h>
#include <vector>

#include <CLI/CLI.hpp>

#include "drapegen/coordinator/job_message.hpp"
#include "drapegen/coordinator/run_config.hpp"
#include "drapegen/sampler/initial_state_recipe.hpp"
#include "drapegen/storage/manifest_reader.hpp"
#include "drapegen/worker/job_runner.hpp"

extern char** environ;
namespace fs = std::filesystem;

namespace {

double now_s() {
  return std::chrono::duration<double>(std::chrono::steady_clock::now().time_since_epoch()).count();
}

pid_t spawn(const std::string& exe, std::vector<std::string> args, const std::string& log) {
  args.insert(args.begin(), exe);
  std::vector<char*> argv;
  for (auto& a : args) argv.push_back(a.data());
  argv.push_back(nullptr);
  posix_spawn_file_actions_t actions;
  posix_spawn_file_actions_init(&actions);
  posix_spawn_file_actions_addopen(&actions, 1, log.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
  posix_spawn_file_actions_addopen(&actions, 2, log.c_str(), O_WRONLY | O_CREAT | O_APPEND, 0644);
  pid_t pid = -1;
  posix_spawn(&pid, exe.c_str(), &actions, nullptr, argv.data(), environ);
  posix_spawn_file_actions_destroy(&actions);
  return pid;
}

/// The next job index from a counter file shared by the loop processes (flock).
long next_index(const std::string& counter) {
  const int fd = ::open(counter.c_str(), O_RDWR | O_CREAT, 0644);
  ::flock(fd, LOCK_EX);
  char buf[32] = {};
  const ssize_t n = ::pread(fd, buf, sizeof buf - 1, 0);
  const long index = n > 0 ? std::strtol(buf, nullptr, 10) : 0;
  const std::string next = std::to_string(index + 1);
  (void)!::ftruncate(fd, 0);
  (void)!::pwrite(fd, next.data(), next.size(), 0);
  ::flock(fd, LOCK_UN);
  ::close(fd);
  return index;
}

std::string slurp(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  std::ostringstream s;
  s << in.rdbuf();
  return s.str();
}

/// One loop process: computes jobs of the service's manifest until the counter runs out.
int loop(const std::string& manifest, const std::string& out, const std::string& counter) {
  auto reader = drapegen::storage::ManifestReader::open(manifest);
  if (!reader) return 1;
  const auto run = reader->run().value();
  const auto config = drapegen::coordinator::parse_run_config(run.config_toml, "stored").value();
  const auto samples = reader->samples().value();
  const auto jobs = reader->jobs().value();
  const std::string data = reader->directory() + "/data";
  drapegen::worker::JobRunner runner(out + "/scratch-" + std::to_string(::getpid()));
  for (long i; (i = next_index(counter)) < static_cast<long>(jobs.size());) {
    const auto& rec = jobs[static_cast<std::size_t>(i)];
    std::string source;
    const auto recipe = drapegen::sampler::recipe_from_json(nlohmann::json::parse(rec.recipe_json));
    if (recipe && recipe->kind == drapegen::sampler::RecipeKind::kDrape) {
      // As `simulate --init mesh:FILE`: the source drape from a file (the service's copy of it).
      source = slurp(data + "/" + drapegen::coordinator::result_stem(recipe->source.sample, recipe->source.slot) +
                     ".ply");
    }
    auto job = drapegen::coordinator::make_job_message(config, samples[static_cast<std::size_t>(rec.sample)], rec,
                                                       1, source);
    const auto answer = runner.run(*job);
    if (answer.body_case() != drapegen::proto::v1::Envelope::kResult) continue;
    const std::string stem = out + "/" + drapegen::coordinator::result_stem(rec.sample, rec.slot);
    std::ofstream(stem + ".ply", std::ios::binary) << answer.result().mesh_ply();
    for (int k = 0; k < answer.result().exr_size(); ++k) {
      std::ofstream(fmt::format("{}_o{:02d}.exr", stem, k), std::ios::binary) << answer.result().exr(k);
    }
  }
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"Service overhead against plain simulate + render loops"};
  std::string config, dir = (fs::temp_directory_path() / "drapegen_service_overhead").string();
  std::string loop_manifest, loop_out, loop_counter;
  int workers = 2;
  app.add_option("--config", config, "Run configuration (its output key is replaced)");
  app.add_option("--workers", workers, "Workers, and plain loops")->capture_default_str();
  app.add_option("--dir", dir, "Work directory (removed first)")->capture_default_str();
  app.add_option("--loop-manifest", loop_manifest)->group("");
  app.add_option("--loop-out", loop_out)->group("");
  app.add_option("--loop-counter", loop_counter)->group("");
  CLI11_PARSE(app, argc, argv);
  if (!loop_manifest.empty()) return loop(loop_manifest, loop_out, loop_counter);
  if (config.empty()) {
    std::fprintf(stderr, "--config is required\n");
    return 1;
  }
  fs::remove_all(dir);
  fs::create_directories(dir + "/loop");
  const std::string self = fs::read_symlink("/proc/self/exe").string();

  double t0 = now_s();
  const pid_t local = spawn(DRAPEGEN_BIN,
                            {"local", "--workers", std::to_string(workers), "--config", config, "--output",
                             dir + "/service"},
                            dir + "/service.log");
  int status = 0;
  ::waitpid(local, &status, 0);
  const double service = now_s() - t0;
  if (!WIFEXITED(status) || WEXITSTATUS(status) != 0) {
    std::fprintf(stderr, "drapegen local failed; see %s/service.log\n", dir.c_str());
    return 1;
  }
  const std::string manifest = dir + "/service/manifest.sqlite";
  const auto jobs = drapegen::storage::ManifestReader::open(manifest)->jobs().value();

  t0 = now_s();
  std::vector<pid_t> loops;
  for (int k = 0; k < workers; ++k) {
    loops.push_back(spawn(self,
                          {"--loop-manifest", manifest, "--loop-out", dir + "/loop", "--loop-counter",
                           dir + "/loop/counter"},
                          dir + fmt::format("/loop{}.log", k)));
  }
  for (pid_t pid : loops) ::waitpid(pid, nullptr, 0);
  const double plain = now_s() - t0;
  std::printf("%zu drapes, %d workers: drapegen local %.1f s (%.0f drapes/hour), plain loops %.1f s (%.0f "
              "drapes/hour): service / loops = %.3f\n",
              jobs.size(), workers, service, 3600.0 * static_cast<double>(jobs.size()) / service, plain,
              3600.0 * static_cast<double>(jobs.size()) / plain, service / plain);
  return 0;
}
