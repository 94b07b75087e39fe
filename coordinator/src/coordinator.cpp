#include "drapegen/coordinator/coordinator.hpp"

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <deque>
#include <filesystem>
#include <fmt/format.h>
#include <map>
#include <optional>
#include <set>
#include <unistd.h>
#include <unordered_map>
#include <unordered_set>
#include <utility>
#include <zmq.hpp>
#include <zmq_addon.hpp>

#include "drapegen/build_id.hpp"
#include "curve_server.hpp"
#include "worker_peers.hpp"
#include "drapegen/coordinator/curve_keys.hpp"
#include "drapegen/coordinator/job_message.hpp"
#include "drapegen/coordinator/logging.hpp"
#include "drapegen/coordinator/planner.hpp"
#include "drapegen/proto/codec.hpp"
#include "drapegen/proto/recipe.hpp"
#include "drapegen/sim/blas_kernels.hpp"
#include "drapegen/storage/atomic_file.hpp"
#include "drapegen/storage/read_file.hpp"
#include "drapegen/storage/manifest.hpp"
#include "drapegen/storage/output_lock.hpp"
#include "drapegen/storage/sha256.hpp"

namespace drapegen::coordinator {
namespace v1 = proto::v1;
namespace fs = std::filesystem;
using Clock = std::chrono::steady_clock;

namespace {

/// The error, as the file system's (sim::Error::io): the output could not be created or written.
sim::Error io_error(sim::Error e) {
  e.io = true;
  return e;
}

double unix_now() {
  return std::chrono::duration<double>(std::chrono::system_clock::now().time_since_epoch()).count();
}

std::string format_duration(double seconds) {
  if (!(seconds >= 0.0) || seconds > 1e8) return "?";
  const auto s = static_cast<long>(seconds + 0.5);
  if (s >= 3600) return fmt::format("{}h{:02d}m", s / 3600, (s % 3600) / 60);
  if (s >= 60) return fmt::format("{}m{:02d}s", s / 60, s % 60);
  return fmt::format("{}s", s);
}

}  // namespace

struct Coordinator::Impl {
  struct JobSlot {
    storage::JobRecord rec;
    int attempts = 0;  // attempts started, this session included
    int attempt_limit = 0;  // the job fails at this many attempts (retry.max_attempts; more for a retried job)
    int forgiven_leaves = 0;  // attempts given back by workers that left (stopped), this session
    bool leased = false;
    std::string worker;  // routing id of the lease
    double lease_started = 0.0;
    Clock::time_point deadline;
    std::int64_t waiting_on = 0;  // source job of a drape recipe, while it is pending
    std::vector<std::string> failed_on;  // routing ids of the workers whose attempts failed, this session
  };
  static constexpr int kForgivenLeaves = 3;  // attempts per job given back by leaving workers, per session
  struct Worker {
    std::string identity;
    std::string name;
    Clock::time_point last_seen, last_sent;
    int interval_ms = 1000;
    int liveness = 5;
    std::int64_t job = 0;        // leased job
    std::int64_t stale_job = 0;  // a job whose lease expired while this worker computed it
    std::int64_t completed = 0;
  };

  RunConfig config;
  CoordinatorOptions options;
  std::string manifest_path, out_dir, data_dir;
  std::optional<storage::OutputLock> lock;  // OUTPUT/.lock: this run's alone (released last)
  std::unique_ptr<storage::Manifest> manifest;
  std::vector<storage::SampleRecord> samples;
  std::vector<JobSlot> jobs;  // index = id - 1
  std::set<std::int64_t> ready;
  std::unordered_map<std::int64_t, std::vector<std::int64_t>> dependents;
  std::map<std::string, Worker> workers;
  std::int64_t done = 0, failed = 0;
  std::int64_t recorded = 0, rejected = 0;
  /// The counts as of the last commit: what the manifest holds (a failed commit rolls back what came after).
  std::int64_t committed_done = 0, committed_failed = 0, committed_recorded = 0;
  void counts_committed() {
    committed_done = done;
    committed_failed = failed;
    committed_recorded = recorded;
  }
  std::string storage_error;  // the first storage fault of this session; the run stops on it
  bool files_written = false;

  /// Keeps the first fault: what follows it (a commit on the same failing disk) would only hide its path and cause.
  void storage_fault(const sim::Error& error) {
    if (storage_error.empty()) storage_error = error.message;
  }

  zmq::context_t context{1};
  std::unique_ptr<CurveServer> curve;  // CurveZMQ only: set up before the ROUTER binds
  zmq::socket_t socket{context, zmq::socket_type::router};
  std::string endpoint;

  std::shared_ptr<spdlog::logger> log = logger();
  const std::string blas_kernels = sim::blas_kernels_description();  // a worker's other than these is warned about
  bool terminal_progress = false;
  Clock::time_point start = Clock::now(), last_progress = Clock::now(), last_reject_log{};
  std::int64_t finished_at_start = 0;  // jobs done or failed before this session: not its rate

  // ---------------------------------------------------------------------------------------------------------------
  // Setup

  /// The command line's CurveZMQ keys over the configuration's, and whether the workers can connect with them:
  /// checked before the output is claimed or touched. `resumed`: the configuration is the manifest's stored one.
  sim::Status merge_keys(bool resumed) {
    if (!options.server_secret_key.empty() || !options.authorized_keys.empty()) {
      if (options.server_secret_key.empty() || options.authorized_keys.empty()) {
        return sim::Error{"--server-key and --authorized-keys go together"};
      }
      config.server_secret_key = options.server_secret_key;
      config.authorized_keys = options.authorized_keys;
    }
    if (options.keyless_workers && (config.curve || !config.server_secret_key.empty())) {
      if (resumed) {
        return sim::Error{fmt::format(
            "drapegen {} starts its workers without CurveZMQ keys, and this run's stored configuration has a "
            "[security] section: continue it with drapegen run --resume {} --server-key FILE --authorized-keys FILE "
            "and workers started with --server-key and --key",
            options.command, manifest_path)};
      }
      return sim::Error{fmt::format("drapegen {} starts its workers without CurveZMQ keys, on loopback: remove "
                                    "server_secret_key, authorized_keys and curve = true from the configuration's "
                                    "[security] section (or use drapegen run and start the workers with "
                                    "--server-key and --key)",
                                    options.command)};
    }
    if (config.curve && config.server_secret_key.empty()) {
      return sim::Error{"security.curve = true needs CurveZMQ keys: [security] server_secret_key and "
                        "authorized_keys, or --server-key and --authorized-keys"};
    }
    return {};
  }

  /// CurveZMQ (where there are keys, after merge_keys): the server key on the ROUTER and a ZAP handler that admits
  /// only the authorised worker keys.
  sim::Status setup_curve() {
    if (config.server_secret_key.empty()) return {};
    auto attached = CurveServer::attach(context, socket, config.server_secret_key, config.authorized_keys);
    if (!attached) return attached.error();
    curve = std::move(attached).value();
    log->info("CurveZMQ on: {} authorised worker key(s); server public key {}", curve->authorized(),
              curve->public_key());
    return {};
  }

  sim::Status bind(const std::string& preferred, const std::string& fallback) {
    if (sim::Status s = setup_curve(); !s) return s;
    socket.set(zmq::sockopt::linger, 0);
    socket.set(zmq::sockopt::maxmsgsize, static_cast<int64_t>(proto::kMaxFrameBytes));
    socket.set(zmq::sockopt::sndhwm, 0);
    socket.set(zmq::sockopt::rcvhwm, 0);
    std::string error;
    for (const std::string& candidate : {preferred, fallback}) {
      if (candidate.empty()) continue;
      if (!is_loopback(candidate) && !curve) {
        error = fmt::format(
            "refusing to bind {} without authentication: a non-loopback address needs [security] server_secret_key "
            "and authorized_keys (CurveZMQ; drapegen keygen makes keys)",
            candidate);
        if (candidate != fallback && !fallback.empty()) log->warn("{}; binding {} instead", error, fallback);
        continue;
      }
      try {
        socket.bind(candidate);
        endpoint = socket.get(zmq::sockopt::last_endpoint);
        return {};
      } catch (const zmq::error_t& e) {
        error = fmt::format("cannot bind {}: {}", candidate, e.what());
        if (candidate != fallback && !fallback.empty()) log->warn("{}; binding {} instead", error, fallback);
      }
    }
    return sim::Error{error};
  }

  sim::Status publish_endpoint() {
    if (sim::Status s = storage::write_file_atomic(out_dir + "/endpoint", endpoint + "\n"); !s) return s;
    if (!options.endpoint_file.empty()) return storage::write_file_atomic(options.endpoint_file, endpoint + "\n");
    return {};
  }

  sim::Status load_state() {
    const auto& reader = manifest->reader();
    auto s = reader.samples();
    if (!s) return s.error();
    samples = std::move(s).value();
    auto j = reader.jobs();
    if (!j) return j.error();
    jobs.clear();
    jobs.reserve(j->size());
    for (auto& rec : *j) {
      if (rec.id != static_cast<std::int64_t>(jobs.size()) + 1) return sim::Error{"manifest: job ids not contiguous"};
      JobSlot slot;
      slot.attempts = rec.attempts;
      // max_attempts, or for a job --retry-failed made pending again (its attempts a multiple of max_attempts when it
      // failed) max_attempts more: the next multiple above the attempts it has had, so the budget survives a resume.
      slot.attempt_limit = (rec.attempts / config.max_attempts + 1) * config.max_attempts;
      slot.rec = std::move(rec);
      jobs.push_back(std::move(slot));
    }
    for (const auto& slot : jobs) {
      if (slot.rec.sample < 0 || slot.rec.sample >= static_cast<std::int64_t>(samples.size()) ||
          samples[static_cast<std::size_t>(slot.rec.sample)].sample != slot.rec.sample) {
        return sim::Error{fmt::format("manifest: job {} refers to a missing sample", slot.rec.id)};
      }
    }
    if (sim::Status st = manifest->begin(); !st) return st;
    if (options.retry_failed) {
      // Each failed job gets retry.max_attempts more; its failures stay recorded, its attempt numbers go on.
      auto retried = manifest->retry_failed();
      if (!retried) return retried.error();
      for (auto& slot : jobs) {
        if (slot.rec.state != storage::JobState::kFailed) continue;
        slot.rec.state = storage::JobState::kPending;
        slot.rec.failure_reason.clear();
      }
      log->info("{} failed job(s) pending again, {} more attempt(s) each", *retried, config.max_attempts);
    }
    for (auto& slot : jobs) {
      if (slot.rec.state == storage::JobState::kDone) ++done;
      if (slot.rec.state == storage::JobState::kFailed) ++failed;
      if (slot.rec.state != storage::JobState::kPending) continue;
      auto recipe = sampler::recipe_from_json(nlohmann::json::parse(slot.rec.recipe_json, nullptr, false));
      if (!recipe) return sim::Error{fmt::format("manifest: job {}: {}", slot.rec.id, recipe.error().message)};
      if (recipe->kind == sampler::RecipeKind::kDrape) {
        const std::int64_t source = job_id(config, recipe->source.sample, recipe->source.slot);
        if (source < 1 || source > static_cast<std::int64_t>(jobs.size())) {
          return sim::Error{fmt::format("manifest: job {} has an unknown source drape", slot.rec.id)};
        }
        const auto state = jobs[static_cast<std::size_t>(source - 1)].rec.state;
        if (state == storage::JobState::kPending) {
          slot.waiting_on = source;
          dependents[source].push_back(slot.rec.id);
          continue;
        }
        if (state == storage::JobState::kFailed) {
          if (sim::Status st = fall_back(slot); !st) return st;
        }
      }
      ready.insert(slot.rec.id);
    }
    if (sim::Status st = manifest->set_run_state("running"); !st) return st;
    if (sim::Status st = manifest->set_endpoint(endpoint); !st) return st;
    if (sim::Status st = manifest->commit(); !st) return st;
    finished_at_start = done + failed;
    counts_committed();
    return {};
  }

  /// Creates the output's data directory and takes the output's lock (storage::OutputLock) for this coordinator's
  /// life: before a new run looks for an existing manifest, and before a resumed one removes anything.
  sim::Status claim_output() {
    std::error_code ec;
    fs::create_directories(data_dir, ec);
    if (ec) return io_error(sim::Error{fmt::format("cannot create {}: {}", data_dir, ec.message())});
    auto acquired = storage::OutputLock::acquire(out_dir);
    if (!acquired) return acquired.error();
    lock.emplace(std::move(acquired).value());
    return {};
  }

  /// Removes files in data/ that the manifest does not list (results of a transaction that never committed) and
  /// stray temporary files.
  sim::Status remove_orphans() {
    std::unordered_set<std::string> known;
    if (sim::Status s = manifest->reader().for_each_file(
            [&](const storage::FileRecord& f) { known.insert(fs::path(f.path).filename().string()); });
        !s) {
      return s;
    }
    int removed = 0;
    std::error_code ec;
    for (const auto& entry : fs::directory_iterator(data_dir, ec)) {
      if (!entry.is_regular_file()) continue;
      if (known.count(entry.path().filename().string())) continue;
      fs::remove(entry.path(), ec);
      if (ec) return io_error(sim::Error{fmt::format("cannot remove {}: {}", entry.path().string(), ec.message())});
      ++removed;
    }
    if (ec) return io_error(sim::Error{fmt::format("cannot list {}: {}", data_dir, ec.message())});
    if (removed > 0) log->info("removed {} file(s) of results that were never recorded", removed);
    return {};
  }

  // ---------------------------------------------------------------------------------------------------------------
  // Messages

  void send(const std::string& identity, v1::Envelope envelope) {
    const std::string frame = proto::encode(std::move(envelope));
    try {
      socket.send(zmq::buffer(identity), zmq::send_flags::sndmore);
      socket.send(zmq::buffer(frame), zmq::send_flags::none);
    } catch (const zmq::error_t& e) {
      log->warn("cannot send to worker {}: {}", printable(identity), e.what());
    }
    if (auto it = workers.find(identity); it != workers.end()) it->second.last_sent = Clock::now();
  }

  void send_heartbeat(Worker& w) {
    v1::Envelope e;
    e.mutable_heartbeat()->set_interval_ms(static_cast<std::uint32_t>(config.heartbeat_ms));
    e.mutable_heartbeat()->set_liveness(static_cast<std::uint32_t>(config.liveness));
    send(w.identity, std::move(e));
  }

  /// Heartbeats to the workers that have heard nothing for an interval. Also between the results of one long pass
  /// (each result's files are fsync'ed): on a slow disk a pass can outlast a worker's liveness, and a worker that
  /// hears nothing reconnects and throws its computation away.
  void send_due_heartbeats() {
    const auto now = Clock::now();
    for (auto& [identity, w] : workers) {
      if (now - w.last_sent >= std::chrono::milliseconds(config.heartbeat_ms)) send_heartbeat(w);
    }
  }

  void reject(const std::string& identity, const std::string& why) {
    ++rejected;
    const auto now = Clock::now();
    if (now - last_reject_log > std::chrono::seconds(1)) {  // one line a second at most, whatever a peer sends
      log->warn("dropped a message from {}: {} ({} dropped so far)", printable(identity), why, rejected);
      last_reject_log = now;
    }
  }

  void handle(const std::string& identity, const zmq::message_t& frame) {
    auto decoded = proto::decode(frame.data(), frame.size());
    if (!decoded) return reject(identity, decoded.error().message);
    const v1::Envelope& e = *decoded;
    auto it = workers.find(identity);
    if (e.body_case() == v1::Envelope::kReady) {
      if (it != workers.end()) {
        // A known worker starting over: whatever it held is lost.
        lose_worker(it->second, "worker re-registered");
        workers.erase(it);
      }
      Worker w;
      w.identity = identity;
      w.name = e.ready().worker_name().empty() ? printable(identity) : e.ready().worker_name();
      w.last_seen = w.last_sent = Clock::now();
      if (e.ready().interval_ms() > 0) w.interval_ms = static_cast<int>(e.ready().interval_ms());
      log->info("worker {} joined ({} connected)", w.name, workers.size() + 1);
      warn_if_unlike(*log, w.name, e.ready(), "this coordinator", blas_kernels, "the others'");
      workers.emplace(identity, std::move(w));
      send_heartbeat(workers.at(identity));
      return;
    }
    if (it == workers.end()) {
      if (e.body_case() == v1::Envelope::kResult || e.body_case() == v1::Envelope::kFailure) {
        reject(identity, fmt::format("{} from an unregistered worker", proto::body_name(e)));
      }
      if (auto answer = answer_to_stranger(e)) send(identity, std::move(*answer));
      return;
    }
    Worker& w = it->second;
    w.last_seen = Clock::now();
    switch (e.body_case()) {
      case v1::Envelope::kHeartbeat:
        if (e.heartbeat().interval_ms() > 0) w.interval_ms = static_cast<int>(e.heartbeat().interval_ms());
        if (e.heartbeat().liveness() > 0) w.liveness = static_cast<int>(e.heartbeat().liveness());
        // Idle while its expired lease's answer never came (one connection keeps order: an answer sent before this
        // heartbeat would have cleared it): the answer was lost or dropped, and the worker is free, not stuck.
        if (w.stale_job != 0 && e.heartbeat().job_id() == 0) {
          log->info("worker {} is idle without having answered job {} (its lease expired): free again", w.name,
                    w.stale_job);
          w.stale_job = 0;
        }
        return;
      case v1::Envelope::kResult:
        return on_result(w, e.result());
      case v1::Envelope::kFailure:
        return on_failure(w, e.failure());
      case v1::Envelope::kLeave:
        on_leave(w, e.leave());
        workers.erase(it);
        return;
      default:
        return reject(identity, fmt::format("unexpected {} from a worker", proto::body_name(e)));
    }
  }

  /// The slot of the attempt `(job_id, attempt)` if `w` holds its lease; otherwise the message is stale or forged.
  JobSlot* leased_slot(Worker& w, std::uint64_t id, std::uint32_t attempt, const char* what) {
    if (w.stale_job != 0 && static_cast<std::uint64_t>(w.stale_job) == id) {
      w.stale_job = 0;  // the late answer of an expired lease: the worker is free again
      reject(w.identity, fmt::format("{} for job {} after its lease expired", what, id));
      return nullptr;
    }
    if (id == 0 || id > jobs.size()) {
      reject(w.identity, fmt::format("{} for unknown job {}", what, id));
      return nullptr;
    }
    JobSlot& slot = jobs[id - 1];
    if (w.job != static_cast<std::int64_t>(id) || !slot.leased || slot.worker != w.identity ||
        static_cast<std::uint32_t>(slot.attempts) != attempt) {
      reject(w.identity, fmt::format("{} for job {} attempt {}, which this worker does not hold (job state {})", what,
                                     id, attempt, storage::to_string(slot.rec.state)));
      return nullptr;
    }
    return &slot;
  }

  std::string file_name(const JobSlot& slot, const char* suffix) const {
    return result_stem(slot.rec.sample, slot.rec.slot) + suffix;
  }

  /// A result the coordinator cannot record as it came: a failed attempt of its job, for `reason`.
  void refuse_result(Worker& w, const v1::Result& r, v1::FailureReason reason, std::string message) {
    v1::Failure f;
    f.set_job_id(r.job_id());
    f.set_attempt(r.attempt());
    f.set_reason(reason);
    f.set_message(std::move(message));
    on_failure(w, f);
  }

  void on_result(Worker& w, const v1::Result& r) {
    JobSlot* slot = leased_slot(w, r.job_id(), r.attempt(), "result");
    if (!slot) return;
    const bool noop = slot->rec.mode == "noop";
    if (!noop && (r.mesh_ply().empty() || r.exr_size() != config.orientations)) {
      return refuse_result(w, r, v1::FAILURE_REASON_RENDER_ERROR,
                           fmt::format("incomplete result: {} mesh bytes, {} of {} EXR files", r.mesh_ply().size(),
                                       r.exr_size(), config.orientations));
    }
    for (int k = 0; !noop && k < r.exr_size(); ++k) {  // an empty file would be recorded, checksum and all
      if (r.exr(k).empty()) {
        return refuse_result(w, r, v1::FAILURE_REASON_RENDER_ERROR,
                             fmt::format("incomplete result: EXR file {} of {} is empty", k + 1, r.exr_size()));
      }
    }
    // A worker that does not know the run's bending model (older than the field) drapes with the paper's: its result
    // would be mislabelled data, so it counts as a failed attempt and the job goes to another worker.
    const std::string& model = r.metrics().bending_model();
    if (!noop && proto::bending_model_name(model) != config.bending_model) {
      return refuse_result(w, r, v1::FAILURE_REASON_INVALID_JOB,
                           fmt::format("worker {} computed the drape with the {} bending model, the run asks for {} "
                                       "(a worker older than this run's drapegen?)",
                                       w.name, model.empty() ? "dihedral (unnamed)" : model, config.bending_model));
    }
    // Likewise a worker older than JobSpec.renderer renders with OSMesa whatever the run asks.
    if (const std::string& used = r.metrics().renderer(); !noop && proto::renderer_name(used) != config.renderer) {
      return refuse_result(w, r, v1::FAILURE_REASON_INVALID_JOB,
                           fmt::format("worker {} rendered the views with {}, the run asks for {} (a worker older than "
                                       "this run's drapegen?)",
                                       w.name, used.empty() ? "osmesa (unnamed)" : used, config.renderer));
    }
    // Metrics the manifest cannot hold (its REAL columns are NOT NULL; SQLite stores NaN as NULL) make a failed
    // attempt of the job, not a storage error that would stop the run.
    const auto& metrics = r.metrics();
    for (const auto& [name, value] : {std::pair{"residual", metrics.residual()}, {"energy", metrics.energy()},
                                      {"drape_coefficient", metrics.drape_coefficient()},
                                      {"sim_seconds", metrics.sim_seconds()},
                                      {"render_seconds", metrics.render_seconds()}}) {
      if (std::isfinite(value)) continue;
      return refuse_result(w, r, v1::FAILURE_REASON_DIVERGED,
                           fmt::format("result with a non-finite {} ({}) from worker {}", name, value, w.name));
    }
    // Files first (temporary file, fsync, rename); the directory is synced before the manifest commits.
    std::vector<storage::FileRecord> files;
    std::int64_t bytes = 0;
    auto write = [&](const std::string& name, const std::string& data, const char* kind, int index) {
      if (sim::Status s = storage::write_file_atomic(data_dir + "/" + name, data); !s) {
        storage_fault(s.error());
        return false;
      }
      files.push_back({slot->rec.id, kind, index, "data/" + name, storage::sha256_hex(data),
                       static_cast<std::int64_t>(data.size())});
      bytes += static_cast<std::int64_t>(data.size());
      return true;
    };
    if (!noop) {
      if (!write(file_name(*slot, ".ply"), r.mesh_ply(), "mesh", 0)) return;
      for (int k = 0; k < r.exr_size(); ++k) {
        if (!write(file_name(*slot, fmt::format("_o{:02d}.exr", k).c_str()), r.exr(k), "exr", k)) return;
      }
      files_written = true;
    }
    const auto& m = r.metrics();
    storage::ResultRecord result;
    result.job_id = slot->rec.id;
    result.outcome = m.outcome();
    result.iterations = m.iterations();
    result.coarse_iterations = m.coarse_iterations();
    result.residual = m.residual();
    result.energy = m.energy();
    result.drape_coefficient = m.drape_coefficient();
    result.folds = m.folds();
    result.self_intersections = m.self_intersections();
    result.sim_seconds = m.sim_seconds();
    result.render_seconds = m.render_seconds();
    result.bytes = bytes;
    storage::JobRecord rec = slot->rec;
    rec.attempts = slot->attempts;
    rec.worker = w.name;
    rec.started_at = slot->lease_started;
    rec.finished_at = unix_now();
    if (sim::Status s = manifest->begin(); !s) {
      storage_fault(s.error());
      return;
    }
    if (sim::Status s = manifest->record_result(rec, result, files); !s) {
      storage_fault(s.error());
      return;
    }
    rec.state = storage::JobState::kDone;
    slot->rec = rec;
    slot->leased = false;
    slot->worker.clear();
    w.job = 0;
    ++w.completed;
    ++done;
    ++recorded;
    release_dependents(slot->rec.id, true);
  }

  void on_failure(Worker& w, const v1::Failure& f) {
    JobSlot* slot = leased_slot(w, f.job_id(), f.attempt(), "failure");
    if (!slot) return;
    w.job = 0;
    record_failed_attempt(*slot, f.reason(), f.message(), w.name);
  }

  /// A worker stopped by a signal (a scheduler's preemption, say): the job it held was not finished through any fault
  /// of the job's, so it is re-queued and its attempt not counted (nothing of it is recorded).
  void on_leave(Worker& w, const v1::Leave& leave) {
    log->info("worker {} left ({}; {} connected)", w.name, leave.reason().empty() ? "stopped" : leave.reason(),
              workers.size() - 1);
    // The Leave may name no job when the Job sent to it crossed it on the way: that attempt never started either.
    if (w.job == 0) return;
    JobSlot& slot = jobs[static_cast<std::size_t>(w.job - 1)];
    // Forgiven a few times only: a job that outlasts every worker's time limit (a scheduler's --time shorter than the
    // lease) would otherwise be given back for ever and never fail.
    if (slot.forgiven_leaves >= kForgivenLeaves) {
      return lose_worker(w, "stopped while computing it, again");
    }
    ++slot.forgiven_leaves;
    w.job = 0;
    slot.leased = false;
    slot.worker.clear();
    --slot.attempts;
    ready.insert(slot.rec.id);
    log->info("job {} (sample {} slot {}) re-queued; the attempt is not counted", slot.rec.id, slot.rec.sample,
              slot.rec.slot);
  }

  /// Records a failed attempt; re-queues the job or, at the retry limit, fails it.
  void record_failed_attempt(JobSlot& slot, v1::FailureReason reason, const std::string& message,
                             const std::string& worker_name) {
    slot.leased = false;
    if (!slot.worker.empty()) slot.failed_on.push_back(slot.worker);
    slot.worker.clear();
    const bool final = slot.attempts >= slot.attempt_limit;
    storage::JobRecord rec = slot.rec;
    rec.attempts = slot.attempts;
    rec.worker = worker_name;
    rec.started_at = slot.lease_started;
    rec.finished_at = unix_now();
    // A reason this build does not know (a newer worker's) is kept as "unspecified" with its number, not refused.
    const std::string reason_text = proto::reason_name(reason);
    const bool unknown = reason_text == "unspecified" && reason != v1::FAILURE_REASON_UNSPECIFIED;
    storage::FailureRecord failure{rec.id, slot.attempts, reason_text,
                                   unknown ? fmt::format("(reason {}) {}", static_cast<int>(reason), message) : message,
                                   worker_name, rec.finished_at};
    if (sim::Status s = manifest->begin(); !s) {
      storage_fault(s.error());
      return;
    }
    if (sim::Status s = manifest->record_failure(rec, failure, final); !s) {
      storage_fault(s.error());
      return;
    }
    ++recorded;
    if (final) {
      rec.state = storage::JobState::kFailed;
      rec.failure_reason = failure.reason;
      slot.rec = rec;
      ++failed;
      log->warn("job {} (sample {} slot {}) failed after {} attempt(s): {}: {}", rec.id, rec.sample, rec.slot,
                slot.attempts, failure.reason, message);
      release_dependents(rec.id, false);
    } else {
      slot.rec.attempts = slot.attempts;
      log->info("job {} attempt {} failed ({}: {}); re-queued", rec.id, slot.attempts, failure.reason, message);
      ready.insert(rec.id);
    }
  }

  /// A kDrape job whose source failed starts from its fallback recipe instead (recorded in the manifest).
  sim::Status fall_back(JobSlot& slot, const char* why = "failed") {
    const auto recipe = fallback_recipe(config, slot.rec.sample, slot.rec.slot);
    slot.rec.recipe_json = sampler::to_json(recipe).dump();
    log->info("job {}: its source drape {}; falling back to a {} recipe", slot.rec.id, why,
              sampler::to_string(recipe.kind));
    return manifest->update_recipe(slot.rec.id, slot.rec.recipe_json);
  }

  void release_dependents(std::int64_t source, bool source_done) {
    auto it = dependents.find(source);
    if (it == dependents.end()) return;
    for (std::int64_t id : it->second) {
      JobSlot& slot = jobs[static_cast<std::size_t>(id - 1)];
      slot.waiting_on = 0;
      if (!source_done) {
        if (sim::Status s = fall_back(slot); !s) {
          storage_fault(s.error());
          return;
        }
      }
      ready.insert(id);
    }
    dependents.erase(it);
  }

  void lose_worker(Worker& w, const char* why) {
    if (w.job != 0) {
      JobSlot& slot = jobs[static_cast<std::size_t>(w.job - 1)];
      w.job = 0;
      record_failed_attempt(slot, v1::FAILURE_REASON_WORKER_LOST, fmt::format("{}: {}", w.name, why), w.name);
    }
  }

  // ---------------------------------------------------------------------------------------------------------------
  // Dispatch and timers

  sim::Expected<v1::Envelope> make_job(JobSlot& slot) {
    auto recipe = sampler::recipe_from_json(nlohmann::json::parse(slot.rec.recipe_json, nullptr, false));
    if (!recipe) return sim::Error{fmt::format("job {}: {}", slot.rec.id, recipe.error().message)};
    std::string source_mesh;
    if (recipe->kind == sampler::RecipeKind::kDrape && slot.rec.mode != "noop") {
      const JobSlot& source = jobs[static_cast<std::size_t>(job_id(config, recipe->source.sample,
                                                                    recipe->source.slot) - 1)];
      const std::string path = data_dir + "/" + file_name(source, ".ply");
      auto bytes = storage::read_file(path);
      if (bytes && !bytes->empty()) {
        source_mesh = std::move(*bytes);
      } else {
        // A done source whose file is gone or unreadable (removed, a disk error): the job starts as if its source
        // had failed, rather than the run stopping on it at every resume.
        log->warn("job {}: its source drape {} cannot be read ({}); the data set lacks that file", slot.rec.id, path,
                  bytes ? "empty file" : bytes.error().message);
        if (sim::Status s = manifest->begin(); !s) return s.error();
        if (sim::Status s = fall_back(slot, "cannot be read"); !s) return s.error();
      }
    }
    auto job = make_job_message(config, samples[static_cast<std::size_t>(slot.rec.sample)], slot.rec, slot.attempts,
                                std::move(source_mesh));
    if (!job) return job.error();
    v1::Envelope e;
    *e.mutable_job() = std::move(job).value();
    return e;
  }

  /// The ready job for a free worker: the first one it has not failed, or one it has failed if every other worker
  /// has too or is stuck on a job whose lease expired (a retry goes to another worker when there is one: a worker
  /// with a full scratch directory or a broken renderer would otherwise spend every attempt of the job it just
  /// failed, freed first as it is; a busy worker is free within a lease).
  std::set<std::int64_t>::iterator next_job_for(const std::string& identity) {
    for (auto it = ready.begin(); it != ready.end(); ++it) {
      const auto& failed_on = jobs[static_cast<std::size_t>(*it - 1)].failed_on;
      if (std::find(failed_on.begin(), failed_on.end(), identity) == failed_on.end()) return it;
      const bool another = std::any_of(workers.begin(), workers.end(), [&](const auto& entry) {
        return entry.second.stale_job == 0 &&
               std::find(failed_on.begin(), failed_on.end(), entry.first) == failed_on.end();
      });
      if (!another) return it;
    }
    return ready.end();
  }

  void dispatch() {
    if (ready.empty()) return;
    for (auto& [identity, w] : workers) {
      if (ready.empty()) return;
      if (w.job != 0 || w.stale_job != 0) continue;
      const auto next = next_job_for(identity);
      if (next == ready.end()) continue;
      const std::int64_t id = *next;
      ready.erase(next);
      JobSlot& slot = jobs[static_cast<std::size_t>(id - 1)];
      ++slot.attempts;
      auto job = make_job(slot);
      if (!job) {
        storage_fault(job.error());
        return;
      }
      slot.leased = true;
      slot.worker = identity;
      slot.lease_started = unix_now();
      slot.deadline = Clock::now() + std::chrono::milliseconds(static_cast<long>(config.lease_s * 1000.0));
      w.job = id;
      send(identity, std::move(job).value());
    }
  }

  void timers() {
    const auto now = Clock::now();
    for (auto it = workers.begin(); it != workers.end();) {
      Worker& w = it->second;
      const auto silence = std::chrono::milliseconds(static_cast<long>(w.interval_ms) * config.liveness);
      if (now - w.last_seen > silence) {
        log->warn("worker {} lost (silent for {} ms)", w.name,
                  std::chrono::duration_cast<std::chrono::milliseconds>(now - w.last_seen).count());
        lose_worker(w, "silent beyond its liveness");
        it = workers.erase(it);
        continue;
      }
      if (w.job != 0) {
        JobSlot& slot = jobs[static_cast<std::size_t>(w.job - 1)];
        if (now > slot.deadline) {
          const std::int64_t id = w.job;
          w.job = 0;
          w.stale_job = id;
          record_failed_attempt(slot, v1::FAILURE_REASON_TIMEOUT,
                                fmt::format("no result within the lease of {} s", config.lease_s), w.name);
        }
      }
      ++it;
    }
    send_due_heartbeats();
  }

  void progress(bool force) {
    if (options.progress == CoordinatorOptions::Progress::kOff) return;
    const auto now = Clock::now();
    const double interval = terminal_progress ? 0.5 : config.progress_interval_s;
    if (!force && std::chrono::duration<double>(now - last_progress).count() < interval) return;
    last_progress = now;
    const double elapsed = std::chrono::duration<double>(now - start).count();
    const std::int64_t total = static_cast<std::int64_t>(jobs.size());
    const double rate = elapsed > 0 ? static_cast<double>(done + failed - finished_at_start) / elapsed : 0.0;
    const std::int64_t left = total - done - failed;
    const std::string eta = rate > 0 ? format_duration(static_cast<double>(left) / rate) : "?";
    const std::string line =
        fmt::format("{}/{} done, {} failed, {:.2f} jobs/s, ETA {}, {} worker(s), {} in flight", done, total, failed,
                    rate, eta, workers.size(),
                    std::count_if(workers.begin(), workers.end(), [](const auto& w) { return w.second.job != 0; }));
    if (terminal_progress) {
      std::fprintf(stderr, "\r\033[K%s", line.c_str());
      std::fflush(stderr);
    } else {
      log->info("progress: {}", line);
    }
  }

  /// Files of this pass are durable (directory synced) before the manifest commits them.
  void commit() {
    if (!manifest->in_transaction()) return;
    if (files_written) {
      if (sim::Status s = storage::sync_directory(data_dir); !s) {
        storage_fault(s.error());
        manifest->rollback();
        return;
      }
      files_written = false;
    }
    if (sim::Status s = manifest->commit(); !s) {
      storage_fault(s.error());
      return;
    }
    counts_committed();
  }

  /// Tells every worker to exit; `stopped`: the run is not over (a worker may serve its resumption).
  void shutdown_workers(const std::string& reason, bool stopped) {
    for (auto& [identity, w] : workers) {
      v1::Envelope e;
      e.mutable_shutdown()->set_reason(reason);
      e.mutable_shutdown()->set_stopped(stopped);
      send(identity, std::move(e));
    }
    // Answer late or reconnecting workers with Shutdown for a moment too.
    const auto until = Clock::now() + std::chrono::milliseconds(options.shutdown_linger_ms);
    while (Clock::now() < until) {
      zmq::pollitem_t items[2] = {{socket.handle(), 0, ZMQ_POLLIN, 0},
                                  {curve ? curve->socket().handle() : nullptr, 0, ZMQ_POLLIN, 0}};
      try {
        zmq::poll(items, curve ? 2 : 1, std::chrono::milliseconds(50));
      } catch (const zmq::error_t&) {
        break;
      }
      if (curve && (items[1].revents & ZMQ_POLLIN)) curve->answer();
      if (!(items[0].revents & ZMQ_POLLIN)) continue;
      std::vector<zmq::message_t> frames;
      if (!zmq::recv_multipart(socket, std::back_inserter(frames), zmq::recv_flags::dontwait)) continue;
      if (frames.empty()) continue;
      v1::Envelope e;
      e.mutable_shutdown()->set_reason(reason);
      e.mutable_shutdown()->set_stopped(stopped);
      send(frames[0].to_string(), std::move(e));
    }
  }

  RunSummary summary(RunOutcome outcome) {
    RunSummary s;
    s.outcome = outcome;
    s.message = storage_error;
    s.total = static_cast<std::int64_t>(jobs.size());
    // What the manifest holds: after a storage fault, records not committed are gone (resume computes them again).
    s.done = committed_done;
    s.failed = committed_failed;
    s.recorded_this_session = committed_recorded;
    s.rejected_messages = rejected;
    s.seconds = std::chrono::duration<double>(Clock::now() - start).count();
    return s;
  }

  RunSummary loop(const std::atomic<bool>& stop) {
    start = last_progress = Clock::now();
    progress(true);
    const auto total = static_cast<std::int64_t>(jobs.size());
    std::vector<zmq::message_t> frames;
    while (true) {
      if (!storage_error.empty()) break;
      if (done + failed == total) break;
      if (stop.load()) break;
      dispatch();
      if (!storage_error.empty()) break;
      zmq::pollitem_t items[2] = {{socket.handle(), 0, ZMQ_POLLIN, 0},
                                  {curve ? curve->socket().handle() : nullptr, 0, ZMQ_POLLIN, 0}};
      zmq::pollitem_t& item = items[0];
      try {
        zmq::poll(items, curve ? 2 : 1, std::chrono::milliseconds(std::min(config.heartbeat_ms, 100)));
      } catch (const zmq::error_t& e) {
        if (e.num() != EINTR) throw;
        continue;  // a signal: the loop condition sees the stop flag
      }
      if (curve && (items[1].revents & ZMQ_POLLIN)) curve->answer();
      if (item.revents & ZMQ_POLLIN) {
        // Drain what has arrived (up to a bound), then commit once: group commit.
        for (int n = 0; n < 1024 && storage_error.empty(); ++n) {
          frames.clear();
          std::optional<std::size_t> got;
          try {
            got = zmq::recv_multipart(socket, std::back_inserter(frames), zmq::recv_flags::dontwait);
          } catch (const zmq::error_t& e) {
            if (e.num() == EINTR) break;
            throw;
          }
          if (!got) break;
          if (frames.size() != 2) {
            reject(frames.empty() ? std::string() : frames[0].to_string(),
                   fmt::format("{} frames (expected one after the routing id)", frames.size() - 1));
            continue;
          }
          handle(frames[0].to_string(), frames[1]);
          if (done + failed == total) break;
          // A freed worker gets its next lease at once, before this pass commits: the commit's fsync overlaps
          // with its computation. (Safe: a lease is never persisted, and a result is only ever committed after
          // the results it depends on, in the same or an earlier commit.)
          dispatch();
          send_due_heartbeats();
        }
      }
      // After a fault, no new lease times out or worker is lost; what this pass recorded before it commits.
      if (storage_error.empty()) timers();
      commit();
      progress(false);
    }
    RunOutcome outcome = RunOutcome::kComplete;
    std::string reason = "the run is complete";
    if (!storage_error.empty()) {
      outcome = RunOutcome::kStorageError;
      reason = "the coordinator stopped on a storage error";
      manifest->rollback();
      // Best effort: the manifest may be on the failing disk too.
      if (manifest->begin() && manifest->set_run_state("stopped")) (void)manifest->commit();
    } else if (done + failed < total) {
      outcome = RunOutcome::kStopped;
      reason = "the coordinator was stopped";
      commit();
      if (manifest->begin() && manifest->set_run_state("stopped")) commit();
    } else {
      commit();
      if (manifest->begin() && manifest->set_run_state("complete")) commit();
    }
    if (!storage_error.empty() && outcome != RunOutcome::kStorageError) outcome = RunOutcome::kStorageError;
    progress(true);
    if (terminal_progress) std::fprintf(stderr, "\n");
    if (rejected > 0) log->warn("{} message(s) dropped during this session (undecodable, stale or forged)", rejected);
    shutdown_workers(reason, outcome != RunOutcome::kComplete);
    return summary(outcome);
  }
};

Coordinator::Coordinator(std::unique_ptr<Impl> impl) : impl_(std::move(impl)) {}
Coordinator::~Coordinator() = default;

namespace {

void setup_progress(Coordinator::Impl& impl) {
  using P = CoordinatorOptions::Progress;
  impl.terminal_progress = impl.options.progress == P::kTerminal ||
                           (impl.options.progress == P::kAuto && ::isatty(STDERR_FILENO) == 1);
  if (impl.terminal_progress) set_terminal_pattern(true);
}

}  // namespace

sim::Expected<std::unique_ptr<Coordinator>> Coordinator::create(const std::string& config_text,
                                                                const std::string& config_name,
                                                                const CoordinatorOptions& options) {
  if (options.retry_failed) return sim::Error{"a new run has no failed jobs to retry (retry_failed is for a resume)"};
  auto config = parse_run_config(config_text, config_name);
  if (!config) return config.error();
  if (sim::Status s = check_new_run(*config, config_name); !s) return s.error();
  auto impl = std::make_unique<Impl>();
  impl->config = *config;
  impl->options = options;
  setup_progress(*impl);
  impl->out_dir = config->output;
  impl->data_dir = config->output + "/data";
  impl->manifest_path = config->output + "/manifest.sqlite";
  if (sim::Status s = impl->merge_keys(false); !s) return s.error();
  if (sim::Status s = impl->claim_output(); !s) return s.error();
  // Checked under the lock: no other coordinator creates it meanwhile.
  if (fs::exists(impl->manifest_path)) {
    return sim::Error{fmt::format("{} exists already: continue it with drapegen {} --resume {}", impl->manifest_path,
                                  options.command, impl->manifest_path)};
  }
  // Files no manifest lists (an earlier run's whose manifest is gone) would sit among this run's, some under the
  // same names as its results and some not: a data set of two runs that the manifest does not show.
  std::error_code ec;
  for (const auto& entry : fs::directory_iterator(impl->data_dir, ec)) {
    if (!entry.is_regular_file(ec)) continue;
    return sim::Error{fmt::format("{} holds files that no manifest lists (an earlier run's?, {} among them): move "
                                  "them away or choose another output",
                                  impl->data_dir, entry.path().filename().string())};
  }
  if (ec) return io_error(sim::Error{fmt::format("cannot list {}: {}", impl->data_dir, ec.message())});
  // Bind before planning, so a taken port fails fast and leaves no manifest behind.
  if (sim::Status s = impl->bind(options.bind_override.empty() ? config->bind : options.bind_override, ""); !s) {
    return s.error();
  }
  impl->log->info("planning {} samples x {} initial states (seed {})", config->samples, config->states_per_sample,
                  config->seed);
  auto plan = plan_run(*config);
  if (!plan) return plan.error();
  storage::RunRecord run;
  run.created_at = unix_now();
  run.seed = config->seed;
  run.config_toml = config_text;
  run.code_version = DRAPEGEN_BUILD_ID;
  run.endpoint = impl->endpoint;
  auto manifest = storage::Manifest::create(impl->manifest_path, run, plan->samples, plan->jobs);
  if (!manifest) return manifest.error();  // the file system's failures are marked io where they arise
  impl->manifest = std::make_unique<storage::Manifest>(std::move(manifest).value());
  if (sim::Status s = impl->load_state(); !s) return s.error();
  impl->log->info("run planned: {} jobs in {}; listening on {}", impl->jobs.size(), impl->manifest_path,
                  impl->endpoint);
  if (sim::Status s = impl->publish_endpoint(); !s) return s.error();
  return std::unique_ptr<Coordinator>(new Coordinator(std::move(impl)));
}

sim::Expected<std::unique_ptr<Coordinator>> Coordinator::resume(const std::string& manifest_path,
                                                                const CoordinatorOptions& options) {
  auto manifest = storage::Manifest::open(manifest_path);
  if (!manifest) return manifest.error();
  auto run = manifest->reader().run();
  if (!run) return run.error();
  auto config = parse_run_config(run->config_toml, manifest_path + " (stored configuration)");
  if (!config) return config.error();
  auto impl = std::make_unique<Impl>();
  impl->config = *config;
  impl->options = options;
  setup_progress(*impl);
  impl->manifest_path = manifest_path;
  impl->out_dir = manifest->reader().directory();
  impl->data_dir = impl->out_dir + "/data";
  impl->manifest = std::make_unique<storage::Manifest>(std::move(manifest).value());
  if (sim::Status s = impl->merge_keys(true); !s) return s.error();
  // Before anything is removed: the files a live run has not yet recorded are not orphans.
  if (sim::Status s = impl->claim_output(); !s) return s.error();
  if (sim::Status s = impl->remove_orphans(); !s) return s.error();
  const std::string preferred = options.bind_override.empty() ? run->endpoint : options.bind_override;
  if (sim::Status s = impl->bind(preferred, options.bind_override.empty() ? config->bind : ""); !s) return s.error();
  if (sim::Status s = impl->load_state(); !s) return s.error();
  impl->log->info("resumed {}: {} of {} jobs done, {} failed; listening on {}", manifest_path, impl->done,
                  impl->jobs.size(), impl->failed, impl->endpoint);
  // The stored configuration is the text as given: keys it leaves out take this build's defaults.
  if (run->code_version != DRAPEGEN_BUILD_ID) {
    impl->log->warn("the run was planned by drapegen {} and is resumed by {}: its remaining jobs are computed with "
                    "this build's code and the defaults of the keys its configuration leaves out (drapegen local "
                    "--print-config shows them)",
                    run->code_version, DRAPEGEN_BUILD_ID);
  }
  if (sim::Status s = impl->publish_endpoint(); !s) return s.error();
  // Last, holding the run's lock, once nothing before the run can fail: an older build refuses the upgraded file.
  // (Nothing above writes a failure, the only rows version 1 cannot hold.)
  if (const int from = impl->manifest->schema_version(); from != storage::kSchemaVersion) {
    if (sim::Status s = impl->manifest->upgrade_schema(); !s) return s.error();
    impl->log->info("manifest upgraded from schema version {} to {}", from, storage::kSchemaVersion);
  }
  return std::unique_ptr<Coordinator>(new Coordinator(std::move(impl)));
}

const std::string& Coordinator::endpoint() const { return impl_->endpoint; }
const std::string& Coordinator::manifest_path() const { return impl_->manifest_path; }
const RunConfig& Coordinator::config() const { return impl_->config; }

RunSummary Coordinator::run(const std::atomic<bool>& stop) { return impl_->loop(stop); }

}  // namespace drapegen::coordinator
