#include "drapegen/worker/worker.hpp"

#include <algorithm>
#include <atomic>
#include <chrono>
#include <condition_variable>
#include <filesystem>
#include <fmt/format.h>
#include <functional>
#include <memory>
#include <mutex>
#include <optional>
#include <thread>
#include <csignal>
#include <cerrno>
#include <cstdlib>
#include <unistd.h>
#include <zmq.hpp>

#include "drapegen/build_id.hpp"
#include "drapegen/coordinator/curve_keys.hpp"
#include "drapegen/coordinator/logging.hpp"
#include "drapegen/proto/codec.hpp"
#include "drapegen/proto/text.hpp"
#include "drapegen/sim/blas_kernels.hpp"
#include "drapegen/storage/atomic_file.hpp"
#include "drapegen/worker/job_runner.hpp"

namespace drapegen::worker {
namespace v1 = proto::v1;
using Clock = std::chrono::steady_clock;
using std::chrono::milliseconds;

namespace {

/// The computing thread: one job at a time, its answer picked up by the I/O loop. The thread shares the state (and
/// the runner, whose OSMesa contexts belong to it) with the executor: a worker stopped mid-job detaches the thread,
/// which finishes its job on state it still owns and releases it last.
class Executor {
 public:
  explicit Executor(std::string scratch)
      : state_(std::make_shared<State>(std::move(scratch))), thread_([state = state_] { loop(*state); }) {}
  ~Executor() {
    {
      std::lock_guard lock(state_->mutex);
      state_->quit = true;
    }
    state_->cv.notify_all();
    if (state_->busy) {
      thread_.detach();  // a computation cannot be interrupted; the process exits without waiting for it
    } else {
      thread_.join();
    }
  }
  Executor(const Executor&) = delete;
  Executor& operator=(const Executor&) = delete;
  void submit(v1::Job job) {
    {
      std::lock_guard lock(state_->mutex);
      state_->job = std::move(job);
      state_->busy = true;
    }
    state_->cv.notify_all();
  }
  [[nodiscard]] bool busy() const { return state_->busy; }
  std::optional<v1::Envelope> take() {
    std::lock_guard lock(state_->mutex);
    std::optional<v1::Envelope> out = std::move(state_->answer);
    state_->answer.reset();
    if (out) state_->busy = false;
    return out;
  }

 private:
  struct State {
    explicit State(std::string scratch) : runner(std::move(scratch)) {}
    JobRunner runner;
    std::mutex mutex;
    std::condition_variable cv;
    std::optional<v1::Job> job;
    std::optional<v1::Envelope> answer;
    std::atomic<bool> busy{false};
    bool quit = false;
  };

  static void loop(State& state) {
    for (;;) {
      v1::Job job;
      {
        std::unique_lock lock(state.mutex);
        state.cv.wait(lock, [&] { return state.quit || state.job.has_value(); });
        if (state.quit) return;
        job = std::move(*state.job);
        state.job.reset();
      }
      v1::Envelope answer = state.runner.run(job);
      std::lock_guard lock(state.mutex);
      state.answer = std::move(answer);
    }
  }

  std::shared_ptr<State> state_;
  std::thread thread_;
};

std::string default_name() {
  char host[256] = {};
  ::gethostname(host, sizeof host - 1);
  return fmt::format("{}:{}", host, ::getpid());
}

}  // namespace

sim::Expected<WorkerEnd> run_worker(const WorkerOptions& o, const std::atomic<bool>& stop) {
  auto log = coordinator::logger();
  const std::string name = o.name.empty() ? default_name() : o.name;
  // The coordinator drops a Ready whose name is too long or not UTF-8, and the worker would register for ever.
  if (name.size() > proto::kMaxReadyText || !proto::is_utf8(name) || name.find_first_of("\r\n") != std::string::npos) {
    return sim::Error{fmt::format("--name must be one line of UTF-8 of at most {} bytes", proto::kMaxReadyText)};
  }
  std::string scratch = o.scratch_dir;
  if (scratch.empty()) {
    // Scratch directories of workers that died without cleaning up (SIGKILL): their process no longer exists.
    std::error_code ec;
    for (const auto& entry : std::filesystem::directory_iterator(std::filesystem::temp_directory_path(), ec)) {
      const std::string name = entry.path().filename().string();
      if (name.rfind("drapegen-worker-", 0) != 0) continue;
      const long pid = std::strtol(name.c_str() + 16, nullptr, 10);
      if (pid > 0 && ::kill(static_cast<pid_t>(pid), 0) != 0 && errno == ESRCH) {
        std::filesystem::remove_all(entry.path(), ec);
      }
    }
    scratch = (std::filesystem::temp_directory_path() / fmt::format("drapegen-worker-{}", ::getpid())).string();
  }
  struct RemoveScratch {
    std::string dir;
    ~RemoveScratch() {
      std::error_code ec;
      std::filesystem::remove_all(dir, ec);
    }
  } remove_scratch{o.scratch_dir.empty() ? scratch : std::string()};
  // A scratch directory the jobs cannot write to would fail every job it takes (as invalid), one after the other:
  // refuse to start instead.
  {
    std::error_code ec;
    std::filesystem::create_directories(scratch, ec);
    // Named per thread: workers in one process (tests, embedders) share the PID's scratch directory.
    const std::string probe = (std::filesystem::path(scratch) /
                               fmt::format("write_probe_{}", std::hash<std::thread::id>{}(std::this_thread::get_id())))
                                  .string();
    if (ec) return sim::Error{fmt::format("scratch directory {}: {}", scratch, ec.message())};
    if (sim::Status s = storage::write_file_atomic(probe, "probe"); !s) {
      return sim::Error{fmt::format("scratch directory {} is not writable: {}", scratch, s.error().message)};
    }
    std::filesystem::remove(probe, ec);
  }
  std::optional<coordinator::CurveKeyPair> own_key;
  std::string server_key;
  if (!o.server_key.empty() || !o.key_file.empty()) {
    if (o.server_key.empty() || o.key_file.empty()) return sim::Error{"CurveZMQ needs both --server-key and --key"};
    auto server = coordinator::read_public_key(o.server_key);
    if (!server) return server.error();
    server_key = *server;
    auto own = coordinator::read_secret_key(o.key_file);
    if (!own) return own.error();
    own_key = *own;
  }
  Executor executor(scratch);
  zmq::context_t context{1};
  // The first reconnect delay, doubled up to the longest: never above the longest, however small that is set.
  const int backoff_initial_ms = std::min(o.backoff_initial_ms, o.backoff_max_ms);
  int backoff_ms = backoff_initial_ms;
  auto last_contact = Clock::now();  // with any coordinator
  std::int64_t current_job = 0;      // job being computed (0: none)
  std::uint32_t current_attempt = 0;

  while (!stop.load()) {
    zmq::socket_t socket(context, zmq::socket_type::dealer);
    socket.set(zmq::sockopt::linger, 0);
    socket.set(zmq::sockopt::maxmsgsize, static_cast<int64_t>(proto::kMaxFrameBytes));
    try {
      if (own_key) {
        socket.set(zmq::sockopt::curve_serverkey, server_key);
        socket.set(zmq::sockopt::curve_publickey, own_key->public_z85);
        socket.set(zmq::sockopt::curve_secretkey, own_key->secret_z85);
      }
      socket.connect(o.endpoint);
    } catch (const zmq::error_t& e) {
      return sim::Error{fmt::format("cannot connect to {}: {}", o.endpoint, e.what())};
    }
    auto send = [&](v1::Envelope e) {
      const std::string frame = proto::encode(std::move(e));
      socket.send(zmq::buffer(frame), zmq::send_flags::dontwait);
    };
    {
      v1::Envelope ready;
      ready.mutable_ready()->set_worker_name(name);
      ready.mutable_ready()->set_code_version(DRAPEGEN_BUILD_ID);
      ready.mutable_ready()->set_blas_kernels(sim::blas_kernels_description());
      ready.mutable_ready()->set_interval_ms(static_cast<std::uint32_t>(o.heartbeat_ms));
      send(std::move(ready));
    }
    // A job computed for an earlier connection is of no use: its lease is gone with that connection. Until it
    // finishes, a job leased on this connection waits in `queued`.
    bool stale_computation = executor.busy();
    std::optional<v1::Job> queued;
    int peer_interval_ms = o.heartbeat_ms;
    auto last_recv = Clock::now();
    auto last_send = Clock::now();
    bool connected = false;  // heard from the coordinator on this socket
    bool reconnect = false;
    while (!stop.load() && !reconnect) {
      zmq::pollitem_t item{socket.handle(), 0, ZMQ_POLLIN, 0};
      const int timeout = executor.busy() ? std::min(o.heartbeat_ms, 20) : std::min(o.heartbeat_ms, 100);
      try {
        zmq::poll(&item, 1, milliseconds(timeout));
      } catch (const zmq::error_t& e) {
        if (e.num() == EINTR) continue;
        throw;
      }
      if (item.revents & ZMQ_POLLIN) {
        zmq::message_t frame;
        while (socket.recv(frame, zmq::recv_flags::dontwait)) {
          auto decoded = proto::decode(frame.data(), frame.size());
          if (!decoded) {
            log->warn("dropped a message from the coordinator: {}", decoded.error().message);
            // A job this build's checks refuse (a newer coordinator's setting, say) is answered as an invalid job:
            // dropped, its lease held on until it expired (15 minutes by default) and the next one went the same way.
            if (auto refused = proto::refused_job(frame.data(), frame.size()); refused && current_job == 0) {
              v1::Envelope f;
              f.mutable_failure()->set_job_id(refused->first);
              f.mutable_failure()->set_attempt(refused->second);
              f.mutable_failure()->set_reason(v1::FAILURE_REASON_INVALID_JOB);
              f.mutable_failure()->set_message("the worker refused the job: " + decoded.error().message);
              send(std::move(f));
              last_send = Clock::now();
            }
            continue;
          }
          last_recv = Clock::now();
          // A coordinator that only says it does not know us is no coordinator for --give-up.
          if (decoded->body_case() != v1::Envelope::kDisconnect) last_contact = last_recv;
          if (!connected) {
            connected = true;
            backoff_ms = backoff_initial_ms;
            log->info("worker {}: connected to {}", name, o.endpoint);
          }
          const v1::Envelope& e = *decoded;
          switch (e.body_case()) {
            case v1::Envelope::kHeartbeat:
              if (e.heartbeat().interval_ms() > 0) peer_interval_ms = static_cast<int>(e.heartbeat().interval_ms());
              break;
            case v1::Envelope::kJob:
              if (current_job != 0) {
                log->warn("worker {}: got job {} while computing job {}; ignored", name, e.job().job_id(),
                          current_job);
                break;
              }
              if (e.job().spec().mode() == v1::JOB_MODE_NOOP) {  // answered at once, no thread hop
                v1::Envelope r;
                r.mutable_result()->set_job_id(e.job().job_id());
                r.mutable_result()->set_attempt(e.job().attempt());
                r.mutable_result()->mutable_metrics()->set_outcome("noop");
                send(std::move(r));
                last_send = Clock::now();
                break;
              }
              current_job = static_cast<std::int64_t>(e.job().job_id());
              current_attempt = e.job().attempt();
              if (executor.busy()) {
                queued = e.job();  // the stale computation still runs; this one starts when it ends
              } else {
                executor.submit(e.job());
              }
              break;
            case v1::Envelope::kDisconnect:
              log->info("worker {}: coordinator does not know us ({}); registering again", name,
                        e.disconnect().reason());
              reconnect = true;
              backoff_ms = 0;
              break;
            case v1::Envelope::kShutdown:
              log->info("worker {}: shutdown ({})", name, e.shutdown().reason());
              return e.shutdown().stopped() ? WorkerEnd::kRunStopped : WorkerEnd::kRunOver;
            default:
              log->warn("worker {}: unexpected {} from the coordinator", name, proto::body_name(e));
              break;
          }
          if (reconnect) break;
        }
      }
      if (auto answer = executor.take()) {
        if (stale_computation) {
          stale_computation = false;
          if (queued) {
            executor.submit(std::move(*queued));
            queued.reset();
          }
        } else if (current_job != 0) {
          send(std::move(*answer));
          last_send = Clock::now();
          current_job = 0;
          current_attempt = 0;
        }
      }
      const auto now = Clock::now();
      if (now - last_send >= milliseconds(o.heartbeat_ms)) {
        v1::Envelope hb;
        hb.mutable_heartbeat()->set_job_id(static_cast<std::uint64_t>(current_job));
        hb.mutable_heartbeat()->set_interval_ms(static_cast<std::uint32_t>(o.heartbeat_ms));
        hb.mutable_heartbeat()->set_liveness(static_cast<std::uint32_t>(o.liveness));
        send(std::move(hb));
        last_send = now;
      }
      if (now - last_recv > milliseconds(static_cast<long>(peer_interval_ms) * o.liveness)) {
        log->warn("worker {}: coordinator at {} silent for {} ms; reconnecting in {} ms", name, o.endpoint,
                  std::chrono::duration_cast<milliseconds>(now - last_recv).count(), backoff_ms);
        reconnect = true;
      }
    }
    if (stop.load()) {
      // Said, so that the job in hand is re-queued at once without costing an attempt, and no other is sent here
      // (also before anything was heard on this socket: the coordinator may have leased a job on our Ready already).
      v1::Envelope leave;
      leave.mutable_leave()->set_job_id(static_cast<std::uint64_t>(current_job));
      leave.mutable_leave()->set_attempt(current_job != 0 ? current_attempt : 0);
      leave.mutable_leave()->set_reason("stopped");
      socket.set(zmq::sockopt::linger, connected ? 1000 : 200);  // sent before the socket closes, if anyone is there
      send(std::move(leave));
      break;
    }
    // The job in flight (if any) belonged to this connection.
    if (current_job != 0) {
      current_job = 0;
      (void)current_attempt;
    }
    // Checked when a connection is given up (after liveness heartbeats of silence, or on a Disconnect), so the wait
    // can exceed it by that and by the last reconnect delay.
    if (const double waited = std::chrono::duration<double>(Clock::now() - last_contact).count();
        o.give_up_s > 0 && waited > o.give_up_s) {
      return sim::Error{fmt::format("no coordinator at {} for {:.1f} s (--give-up {} s); giving up", o.endpoint, waited,
                                    o.give_up_s)};
    }
    const auto until = Clock::now() + milliseconds(backoff_ms);
    while (Clock::now() < until && !stop.load()) std::this_thread::sleep_for(milliseconds(20));
    backoff_ms = std::min(std::max(backoff_ms * 2, backoff_initial_ms), o.backoff_max_ms);
  }
  return WorkerEnd::kStopped;
}

}  // namespace drapegen::worker
