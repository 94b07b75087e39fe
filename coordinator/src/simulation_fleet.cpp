#include "drapegen/coordinator/simulation_fleet.hpp"

#include "curve_server.hpp"
#include "worker_peers.hpp"

#include <algorithm>
#include <chrono>
#include <condition_variable>
#include <deque>
#include <fmt/format.h>
#include <future>
#include <map>
#include <set>
#include <mutex>
#include <thread>
#include <zmq.hpp>
#include <zmq_addon.hpp>

#include "drapegen/coordinator/logging.hpp"
#include "drapegen/proto/codec.hpp"
#include "drapegen/proto/simulation.hpp"
#include "drapegen/sim/blas_kernels.hpp"

namespace drapegen::coordinator {
namespace v1 = proto::v1;
using Clock = std::chrono::steady_clock;

namespace {

/// One drape asked for, from its submission to its answer.
struct Task {
  std::uint64_t id = 0;
  v1::Simulation simulation;
  int attempts = 0;  // started
  int forgiven_leaves = 0;  // attempts given back by workers that left (stopped)
  Clock::time_point queued;
  std::promise<sim::Expected<sim::DrapeResult>> answer;
};

}  // namespace

struct SimulationFleet::Impl {
  static constexpr int kForgivenLeaves = 3;  // attempts per drape given back by leaving workers
  struct Worker {
    std::string identity, name;
    Clock::time_point last_seen, last_sent;
    int interval_ms = 1000;
    std::shared_ptr<Task> task;  // the drape it computes (null: idle)
    Clock::time_point dispatched;  // when it was sent
    bool unfit = false;            // it did not compute a drape it was sent: it gets no more
  };

  FleetOptions options;
  zmq::context_t context{1};
  std::unique_ptr<CurveServer> curve;  // CurveZMQ only: set up before the ROUTER binds
  zmq::socket_t socket{context, zmq::socket_type::router};
  std::string endpoint;
  std::shared_ptr<spdlog::logger> log = logger();
  const std::string blas_kernels = sim::blas_kernels_description();

  // Shared with the callers of simulate().
  mutable std::mutex mutex;
  std::condition_variable workers_changed;
  std::deque<std::shared_ptr<Task>> queue;  // waiting for a worker, oldest first (a lost worker's drape at the front)
  std::uint64_t next_id = 1;
  bool stopping = false;
  Counters counters;

  // The serving thread's alone.
  std::map<std::string, Worker> workers;
  std::set<std::string> names;  // of every worker registered so far
  Clock::time_point last_worker = Clock::now();  // when a worker that takes drapes was last connected
  Clock::time_point last_reject_log{};
  std::atomic<bool> stop{false};
  std::thread thread;

  void send(const std::string& identity, v1::Envelope envelope) {
    const std::string frame = proto::encode(std::move(envelope));
    try {
      socket.send(zmq::buffer(identity), zmq::send_flags::sndmore);
      socket.send(zmq::buffer(frame), zmq::send_flags::none);
    } catch (const zmq::error_t& e) {
      log->warn("fleet: cannot send to worker {}: {}", printable(identity), e.what());
    }
    if (auto it = workers.find(identity); it != workers.end()) it->second.last_sent = Clock::now();
  }

  void heartbeat(const std::string& identity) {
    v1::Envelope e;
    e.mutable_heartbeat()->set_interval_ms(static_cast<std::uint32_t>(options.heartbeat_ms));
    e.mutable_heartbeat()->set_liveness(static_cast<std::uint32_t>(options.liveness));
    send(identity, std::move(e));
  }

  void reject(const std::string& identity, const std::string& why) {
    std::lock_guard lock(mutex);
    ++counters.rejected;
    const auto now = Clock::now();
    if (now - last_reject_log > std::chrono::seconds(1)) {
      log->warn("fleet: dropped a message from {}: {} ({} dropped so far)", printable(identity), why,
                counters.rejected);
      last_reject_log = now;
    }
  }

  void update_worker_count() {
    {
      std::lock_guard lock(mutex);
      counters.workers = static_cast<int>(workers.size());
    }
    workers_changed.notify_all();
  }

  /// The worker is gone: its drape goes to the next free worker, or fails after max_attempts.
  void lose(Worker& w, const char* why) {
    if (!w.task) return;
    std::shared_ptr<Task> task = std::move(w.task);
    std::lock_guard lock(mutex);
    ++counters.lost_attempts;
    if (task->attempts >= options.max_attempts) {
      task->answer.set_value(sim::Error{fmt::format("drape {} lost with {} workers (the last {}: {})", task->id,
                                                    task->attempts, w.name, why)});
    } else {
      queue.push_front(std::move(task));
    }
  }

  void on_ready(const std::string& identity, const v1::Ready& ready) {
    if (auto it = workers.find(identity); it != workers.end()) {
      lose(it->second, "registered again");
      workers.erase(it);
    }
    Worker w;
    w.identity = identity;
    w.name = ready.worker_name().empty() ? printable(identity) : ready.worker_name();
    w.last_seen = w.last_sent = Clock::now();
    if (ready.interval_ms() > 0) w.interval_ms = static_cast<int>(ready.interval_ms());
    log->info("fleet: worker {} joined ({} connected)", w.name, workers.size() + 1);
    warn_if_unlike(*log, w.name, ready, "this diagnosis", blas_kernels, "this process's own");
    names.insert(w.name);
    workers.emplace(identity, std::move(w));
    last_worker = Clock::now();
    {
      std::lock_guard lock(mutex);
      counters.workers_seen = static_cast<int>(names.size());
    }
    update_worker_count();
    heartbeat(identity);
  }

  /// The task `w` holds if the answer is for its attempt; else the answer is stale or forged.
  std::shared_ptr<Task> held(Worker& w, std::uint64_t id, std::uint32_t attempt, const char* what) {
    if (!w.task || w.task->id != id || static_cast<std::uint32_t>(w.task->attempts) != attempt) {
      reject(w.identity, fmt::format("{} for drape {} attempt {}, which this worker does not hold", what, id, attempt));
      return nullptr;
    }
    return std::move(w.task);
  }

  void handle(const std::string& identity, const zmq::message_t& frame) {
    auto decoded = proto::decode(frame.data(), frame.size());
    if (!decoded) return reject(identity, decoded.error().message);
    const v1::Envelope& e = *decoded;
    if (e.body_case() == v1::Envelope::kReady) return on_ready(identity, e.ready());
    auto it = workers.find(identity);
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
        // A worker names the job it computes. One that still names another two intervals after its drape was sent
        // does not have it (it could not read the job, e.g. a build that does not know JOB_MODE_SIMULATE): the drape
        // goes to the next worker, as a lost one's does, and this one gets no more.
        if (w.task && e.heartbeat().job_id() != w.task->id &&
            Clock::now() - w.dispatched > std::chrono::milliseconds(2L * w.interval_ms)) {
          log->warn("fleet: worker {} does not compute the drape it was sent (another build?); it gets no more",
                    w.name);
          lose(w, "it does not compute it");
          w.unfit = true;
        }
        return;
      case v1::Envelope::kResult: {
        auto task = held(w, e.result().job_id(), e.result().attempt(), "result");
        if (!task) return;
        auto drape = proto::from_proto(e.result().drape());
        std::lock_guard lock(mutex);
        if (drape) {
          ++counters.simulated;
          task->answer.set_value(std::move(drape).value());
        } else {
          task->answer.set_value(sim::Error{fmt::format("worker {}: {}", w.name, drape.error().message)});
        }
        return;
      }
      case v1::Envelope::kFailure: {
        auto task = held(w, e.failure().job_id(), e.failure().attempt(), "failure");
        if (!task) return;
        std::lock_guard lock(mutex);
        task->answer.set_value(sim::Error{fmt::format("worker {}: {}", w.name, e.failure().message())});
        return;
      }
      case v1::Envelope::kLeave: {
        // Stopped by a signal: its drape goes to the next worker, the attempt not counted (a few times: a drape that
        // outlasts every worker's time limit would otherwise go round for ever).
        log->info("fleet: worker {} left ({})", w.name, e.leave().reason().empty() ? "stopped" : e.leave().reason());
        if (w.task && w.task->forgiven_leaves >= kForgivenLeaves) {
          lose(w, "stopped while computing it, again");
        } else if (w.task) {
          std::lock_guard lock(mutex);
          ++w.task->forgiven_leaves;
          --w.task->attempts;
          queue.push_front(std::move(w.task));
        }
        workers.erase(it);
        update_worker_count();
        return;
      }
      default:
        return reject(identity, fmt::format("unexpected {} from a worker", proto::body_name(e)));
    }
  }

  void dispatch() {
    for (auto& [identity, w] : workers) {
      if (w.task || w.unfit) continue;
      {
        std::lock_guard lock(mutex);
        if (queue.empty()) return;
        w.task = std::move(queue.front());
        queue.pop_front();
        ++w.task->attempts;
      }
      w.dispatched = Clock::now();
      v1::Envelope e;
      auto* job = e.mutable_job();
      job->set_job_id(w.task->id);
      job->set_attempt(static_cast<std::uint32_t>(w.task->attempts));
      job->set_any_failure_reason(true);
      job->mutable_spec()->set_mode(v1::JOB_MODE_SIMULATE);
      *job->mutable_spec()->mutable_simulation() = w.task->simulation;
      send(identity, std::move(e));
    }
  }

  void timers() {
    const auto now = Clock::now();
    bool changed = false;
    for (auto it = workers.begin(); it != workers.end();) {
      Worker& w = it->second;
      if (now - w.last_seen > std::chrono::milliseconds(static_cast<long>(w.interval_ms) * options.liveness)) {
        log->warn("fleet: worker {} lost (silent for {} ms)", w.name,
                  std::chrono::duration_cast<std::chrono::milliseconds>(now - w.last_seen).count());
        lose(w, "silent beyond its liveness");
        it = workers.erase(it);
        changed = true;
        continue;
      }
      if (now - w.last_sent >= std::chrono::milliseconds(options.heartbeat_ms)) heartbeat(w.identity);
      ++it;
    }
    if (changed) update_worker_count();
    // A worker that gets no more drapes (unfit) counts as none.
    if (std::any_of(workers.begin(), workers.end(), [](const auto& entry) { return !entry.second.unfit; })) {
      last_worker = now;
      return;
    }
    std::lock_guard lock(mutex);
    const auto limit = std::chrono::duration<double>(options.wait_s);
    for (auto it = queue.begin(); it != queue.end();) {
      if (now - std::max((*it)->queued, last_worker) > limit) {
        (*it)->answer.set_value(sim::Error{fmt::format(
            "no worker that computes drapes connected to {} for {} s (start some with: drapegen worker --connect {})",
            endpoint, options.wait_s, endpoint)});
        it = queue.erase(it);
      } else {
        ++it;
      }
    }
  }

  void serve() {
    while (!stop.load()) {
      zmq::pollitem_t items[2] = {{socket.handle(), 0, ZMQ_POLLIN, 0},
                                  {curve ? curve->socket().handle() : nullptr, 0, ZMQ_POLLIN, 0}};
      try {
        zmq::poll(items, curve ? 2 : 1, std::chrono::milliseconds(5));
        if (curve && (items[1].revents & ZMQ_POLLIN)) curve->answer();
        if (items[0].revents & ZMQ_POLLIN) {
          zmq::multipart_t message;
          while (message.recv(socket, static_cast<int>(zmq::recv_flags::dontwait))) {
            if (message.size() != 2) {
              reject(message.empty() ? std::string() : message.front().to_string(), "not one frame");
            } else {
              handle(message[0].to_string(), message[1]);
            }
            message.clear();
          }
        }
      } catch (const zmq::error_t& e) {
        if (e.num() == EINTR) continue;
        log->error("fleet: {}", e.what());
        break;
      }
      dispatch();
      timers();
    }
    v1::Envelope shutdown;
    shutdown.mutable_shutdown()->set_reason("the diagnosis is done");
    for (const auto& [identity, w] : workers) send(identity, shutdown);
    std::lock_guard lock(mutex);
    stopping = true;
    for (auto& [identity, w] : workers) {
      if (w.task) w.task->answer.set_value(sim::Error{"the fleet stopped"});
    }
    for (auto& task : queue) task->answer.set_value(sim::Error{"the fleet stopped"});
    queue.clear();
  }
};

SimulationFleet::SimulationFleet(std::unique_ptr<Impl> impl) : impl_(std::move(impl)) {}

SimulationFleet::~SimulationFleet() {
  impl_->stop = true;
  if (impl_->thread.joinable()) impl_->thread.join();
}

sim::Expected<std::unique_ptr<SimulationFleet>> SimulationFleet::start(const FleetOptions& options) {
  if (options.heartbeat_ms < 1 || options.liveness < 1 || options.max_attempts < 1 || !(options.wait_s > 0)) {
    return sim::Error{"fleet: heartbeat, liveness, attempts and wait must be positive"};
  }
  if (options.server_secret_key.empty() != options.authorized_keys.empty()) {
    return sim::Error{"fleet: a server key and authorised keys go together (CurveZMQ)"};
  }
  const bool curve = !options.server_secret_key.empty();
  if (!curve && !is_loopback(options.bind)) {
    return sim::Error{fmt::format("fleet: refusing to bind {} without authentication: an address other machines can "
                                  "reach needs a server key and authorised worker keys (CurveZMQ; drapegen keygen "
                                  "makes keys)",
                                  options.bind)};
  }
  auto impl = std::make_unique<Impl>();
  impl->options = options;
  if (curve) {
    auto attached =
        CurveServer::attach(impl->context, impl->socket, options.server_secret_key, options.authorized_keys);
    if (!attached) return sim::Error{"fleet: " + attached.error().message};
    impl->curve = std::move(attached).value();
    impl->log->info("fleet: CurveZMQ on: {} authorised worker key(s); server public key {}", impl->curve->authorized(),
                    impl->curve->public_key());
  }
  impl->socket.set(zmq::sockopt::linger, 500);  // the Shutdowns leave before the socket closes
  impl->socket.set(zmq::sockopt::maxmsgsize, static_cast<int64_t>(proto::kMaxFrameBytes));
  try {
    impl->socket.bind(options.bind);
    impl->endpoint = impl->socket.get(zmq::sockopt::last_endpoint);
  } catch (const zmq::error_t& e) {
    return sim::Error{fmt::format("fleet: cannot bind {}: {}", options.bind, e.what())};
  }
  Impl* raw = impl.get();
  impl->thread = std::thread([raw] { raw->serve(); });
  return std::unique_ptr<SimulationFleet>(new SimulationFleet(std::move(impl)));
}

const std::string& SimulationFleet::endpoint() const { return impl_->endpoint; }

sim::Expected<sim::DrapeResult> SimulationFleet::simulate(const sim::DrapeConfig& config) {
  auto wire = proto::to_proto(config);
  if (!wire) return wire.error();
  // What a worker would refuse to read is refused here (a worker that cannot read its job answers nothing).
  if (auto readable = proto::from_proto(*wire); !readable) return readable.error();
  auto task = std::make_shared<Task>();
  task->simulation = std::move(wire).value();
  task->queued = Clock::now();
  auto answer = task->answer.get_future();
  {
    std::lock_guard lock(impl_->mutex);
    if (impl_->stopping) return sim::Error{"the fleet stopped"};
    task->id = impl_->next_id++;
    impl_->queue.push_back(std::move(task));
  }
  return answer.get();
}

int SimulationFleet::wait_for_workers(int count, double timeout_s) {
  std::unique_lock lock(impl_->mutex);
  impl_->workers_changed.wait_for(lock, std::chrono::duration<double>(timeout_s),
                                  [&] { return impl_->counters.workers >= count; });
  return impl_->counters.workers;
}

SimulationFleet::Counters SimulationFleet::counters() const {
  std::lock_guard lock(impl_->mutex);
  return impl_->counters;
}

}  // namespace drapegen::coordinator
