#include <gtest/gtest.h>

#include <atomic>
#include <filesystem>
#include <fstream>
#include <unistd.h>
#include <thread>
#include <vector>
#include <zmq.hpp>

#include "drapegen/coordinator/curve_keys.hpp"
#include "drapegen/coordinator/simulation_fleet.hpp"
#include "drapegen/proto/codec.hpp"
#include "drapegen/worker/worker.hpp"

namespace drapegen::coordinator {
namespace {
namespace v1 = proto::v1;

sim::DrapeConfig small_drape(std::uint64_t seed) {
  sim::DrapeConfig c;
  c.specimen.vertices_x = c.specimen.vertices_y = 9;
  c.specimen.seed = seed;
  c.initial.shape = sim::InitialShape::kSine;
  c.initial.seed = seed;
  c.solver.max_iterations = 200;
  return c;
}

/// `drapegen worker` loops on threads of this process, stopped (and joined) on destruction.
class Workers {
 public:
  /// `keys`: CurveZMQ's server public key and the worker's secret key file (empty: plain).
  Workers(const std::string& endpoint, int count, std::pair<std::string, std::string> keys = {}) {
    for (int i = 0; i < count; ++i) {
      threads_.emplace_back([this, endpoint, i, keys] {
        worker::WorkerOptions o;
        o.endpoint = endpoint;
        o.name = "test-" + std::to_string(i);
        o.heartbeat_ms = 100;
        o.server_key = keys.first;
        o.key_file = keys.second;
        (void)worker::run_worker(o, stop_);
      });
    }
  }
  ~Workers() {
    stop_ = true;
    for (auto& t : threads_) t.join();
  }

 private:
  std::atomic<bool> stop_{false};
  std::vector<std::thread> threads_;
};

FleetOptions fast_options() {
  FleetOptions o;
  o.heartbeat_ms = 50;
  o.liveness = 4;
  o.wait_s = 20.0;
  return o;
}

TEST(SimulationFleet, ComputesDrapesOnItsWorkersAsALocalSolveWould) {
  auto fleet = SimulationFleet::start(fast_options());
  ASSERT_TRUE(fleet) << fleet.error().message;
  Workers workers((*fleet)->endpoint(), 2);
  ASSERT_EQ((*fleet)->wait_for_workers(2, 20.0), 2);
  constexpr int kDrapes = 6;
  std::vector<sim::Expected<sim::DrapeResult>> remote(kDrapes, sim::Error{"not run"});
  std::vector<std::thread> callers;
  for (int t = 0; t < 3; ++t) {
    callers.emplace_back([&, t] {
      for (int k = t; k < kDrapes; k += 3) remote[k] = (*fleet)->simulate(small_drape(k + 1));
    });
  }
  for (auto& c : callers) c.join();
  for (int k = 0; k < kDrapes; ++k) {
    ASSERT_TRUE(remote[k]) << remote[k].error().message;
    auto local = sim::simulate_drape(small_drape(k + 1));
    ASSERT_TRUE(local);
    EXPECT_EQ(remote[k]->mesh.positions, local->mesh.positions) << "drape " << k;
    EXPECT_EQ(remote[k]->report.outcome, local->report.outcome);
  }
  const auto counters = (*fleet)->counters();
  EXPECT_EQ(counters.simulated, kDrapes);
  EXPECT_EQ(counters.workers_seen, 2);
  EXPECT_EQ(counters.lost_attempts, 0);
}

TEST(SimulationFleet, PassesOnWhatTheWorkerCannotBuildAndWhatCannotBeSent) {
  auto fleet = SimulationFleet::start(fast_options());
  ASSERT_TRUE(fleet);
  Workers workers((*fleet)->endpoint(), 1);
  sim::DrapeConfig bad = small_drape(1);
  bad.fabric.alpha.warp = -1.0;
  auto failed = (*fleet)->simulate(bad);
  ASSERT_FALSE(failed);
  EXPECT_NE(failed.error().message.find("worker test-0"), std::string::npos) << failed.error().message;
  const auto before = (*fleet)->counters();
  sim::DrapeConfig mesh = small_drape(1);
  mesh.initial.shape = sim::InitialShape::kMesh;
  const auto unsent = (*fleet)->simulate(mesh);  // refused here, before any worker sees it
  ASSERT_FALSE(unsent);
  EXPECT_NE(unsent.error().message.find("a mesh initial state is not sent"), std::string::npos)
      << unsent.error().message;
  EXPECT_EQ((*fleet)->counters().simulated, before.simulated);
  EXPECT_EQ((*fleet)->counters().lost_attempts, before.lost_attempts);
}

TEST(SimulationFleet, FailsADrapeThatNoWorkerComesFor) {
  FleetOptions o = fast_options();
  o.wait_s = 0.3;
  auto fleet = SimulationFleet::start(o);
  ASSERT_TRUE(fleet);
  auto drape = (*fleet)->simulate(small_drape(1));
  ASSERT_FALSE(drape);
  EXPECT_NE(drape.error().message.find("no worker that computes drapes connected"), std::string::npos)
      << drape.error().message;
}

/// A worker that registers, takes one job and then falls silent.
void take_a_job_and_vanish(const std::string& endpoint, std::atomic<bool>& took) {
  zmq::context_t context{1};
  zmq::socket_t socket(context, zmq::socket_type::dealer);
  socket.set(zmq::sockopt::linger, 0);
  socket.connect(endpoint);
  v1::Envelope ready;
  ready.mutable_ready()->set_worker_name("vanishing");
  ready.mutable_ready()->set_interval_ms(50);
  const std::string frame = proto::encode(ready);
  socket.send(zmq::buffer(frame));
  zmq::message_t message;
  while (socket.recv(message)) {
    auto e = proto::decode(message.data(), message.size());
    if (e && e->body_case() == v1::Envelope::kJob) break;
  }
  took = true;
}

TEST(SimulationFleet, GivesALostWorkersDrapeToTheNextAndFailsItAfterMaxAttempts) {
  auto fleet = SimulationFleet::start(fast_options());
  ASSERT_TRUE(fleet);
  const std::string endpoint = (*fleet)->endpoint();
  std::atomic<bool> took{false};
  std::thread vanishing([&] { take_a_job_and_vanish(endpoint, took); });
  ASSERT_EQ((*fleet)->wait_for_workers(1, 20.0), 1);
  std::optional<Workers> real;
  std::thread starter([&] {
    while (!took) std::this_thread::sleep_for(std::chrono::milliseconds(5));
    real.emplace(endpoint, 1);  // only after the vanishing worker holds the drape
  });
  auto drape = (*fleet)->simulate(small_drape(3));
  starter.join();
  vanishing.join();
  ASSERT_TRUE(drape) << drape.error().message;
  EXPECT_EQ(drape->mesh.positions, sim::simulate_drape(small_drape(3))->mesh.positions);
  EXPECT_EQ((*fleet)->counters().lost_attempts, 1);
  real.reset();

  FleetOptions once = fast_options();
  once.max_attempts = 1;
  auto strict = SimulationFleet::start(once);
  ASSERT_TRUE(strict);
  took = false;
  std::thread vanishing_again([&] { take_a_job_and_vanish((*strict)->endpoint(), took); });
  auto lost = (*strict)->simulate(small_drape(3));
  vanishing_again.join();
  ASSERT_FALSE(lost);
  EXPECT_NE(lost.error().message.find("lost with 1 workers"), std::string::npos) << lost.error().message;
}

/// A worker that registers, takes one job and leaves, naming it (a worker stopped by SIGTERM).
void take_a_job_and_leave(const std::string& endpoint, std::atomic<bool>& took) {
  zmq::context_t context{1};
  zmq::socket_t socket(context, zmq::socket_type::dealer);
  socket.set(zmq::sockopt::linger, 1000);
  socket.connect(endpoint);
  v1::Envelope ready;
  ready.mutable_ready()->set_worker_name("leaving");
  ready.mutable_ready()->set_interval_ms(50);
  socket.send(zmq::buffer(proto::encode(ready)));
  zmq::message_t message;
  while (socket.recv(message)) {
    auto e = proto::decode(message.data(), message.size());
    if (!e || e->body_case() != v1::Envelope::kJob) continue;
    v1::Envelope leave;
    leave.mutable_leave()->set_job_id(e->job().job_id());
    leave.mutable_leave()->set_attempt(e->job().attempt());
    socket.send(zmq::buffer(proto::encode(leave)));
    break;
  }
  took = true;
}

// With one attempt per drape, a worker that leaves mid-drape (stopped) costs it nothing: the next worker computes it.
TEST(SimulationFleet, GivesALeavingWorkersDrapeToTheNextWithoutCountingTheAttempt) {
  FleetOptions once = fast_options();
  once.max_attempts = 1;
  auto fleet = SimulationFleet::start(once);
  ASSERT_TRUE(fleet);
  const std::string endpoint = (*fleet)->endpoint();
  std::atomic<bool> took{false};
  std::thread leaving([&] { take_a_job_and_leave(endpoint, took); });
  ASSERT_EQ((*fleet)->wait_for_workers(1, 20.0), 1);
  std::optional<Workers> real;
  std::thread starter([&] {
    while (!took) std::this_thread::sleep_for(std::chrono::milliseconds(5));
    real.emplace(endpoint, 1);  // only after the leaving worker held the drape
  });
  auto drape = (*fleet)->simulate(small_drape(4));
  starter.join();
  leaving.join();
  ASSERT_TRUE(drape) << drape.error().message;
  EXPECT_EQ(drape->mesh.positions, sim::simulate_drape(small_drape(4))->mesh.positions);
  EXPECT_EQ((*fleet)->counters().lost_attempts, 0);
}

/// A worker that registers, takes one job, and heartbeats on as if it had none (a build that cannot read the job).
void take_a_job_and_ignore_it(const std::string& endpoint, std::atomic<bool>& took, const std::atomic<bool>& stop) {
  zmq::context_t context{1};
  zmq::socket_t socket(context, zmq::socket_type::dealer);
  socket.set(zmq::sockopt::linger, 0);
  socket.connect(endpoint);
  auto send = [&](v1::Envelope e) {
    const std::string frame = proto::encode(std::move(e));
    socket.send(zmq::buffer(frame));
  };
  v1::Envelope ready;
  ready.mutable_ready()->set_worker_name("ignoring");
  ready.mutable_ready()->set_interval_ms(50);
  send(ready);
  while (!stop) {
    zmq::pollitem_t item{socket.handle(), 0, ZMQ_POLLIN, 0};
    zmq::poll(&item, 1, std::chrono::milliseconds(50));
    zmq::message_t message;
    while (socket.recv(message, zmq::recv_flags::dontwait)) {
      auto e = proto::decode(message.data(), message.size());
      if (e && e->body_case() == v1::Envelope::kJob) took = true;
    }
    v1::Envelope beat;
    beat.mutable_heartbeat()->set_interval_ms(50);
    beat.mutable_heartbeat()->set_job_id(0);
    send(beat);
  }
}

/// take_a_job_and_ignore_it on a thread of its own, stopped (and joined) on destruction.
struct IgnoringWorker {
  explicit IgnoringWorker(const std::string& endpoint)
      : thread([this, endpoint] { take_a_job_and_ignore_it(endpoint, took, stop); }) {}
  ~IgnoringWorker() {
    stop = true;
    thread.join();
  }
  std::atomic<bool> took{false}, stop{false};
  std::thread thread;
};

TEST(SimulationFleet, GivesADrapeAWorkerDoesNotComputeToTheNext) {
  auto fleet = SimulationFleet::start(fast_options());
  ASSERT_TRUE(fleet);
  const std::string endpoint = (*fleet)->endpoint();
  IgnoringWorker ignoring(endpoint);
  std::atomic<bool>& took = ignoring.took;
  ASSERT_EQ((*fleet)->wait_for_workers(1, 20.0), 1);
  std::optional<Workers> real;
  std::thread starter([&] {
    while (!took) std::this_thread::sleep_for(std::chrono::milliseconds(5));
    real.emplace(endpoint, 1);
  });
  auto drape = (*fleet)->simulate(small_drape(4));
  starter.join();
  ASSERT_TRUE(drape) << drape.error().message;
  EXPECT_EQ(drape->mesh.positions, sim::simulate_drape(small_drape(4))->mesh.positions);
  EXPECT_EQ((*fleet)->counters().lost_attempts, 1);
  EXPECT_EQ((*fleet)->counters().workers, 2);  // the ignoring worker is still registered, and gets no drape
  EXPECT_TRUE((*fleet)->simulate(small_drape(5)));
  EXPECT_EQ((*fleet)->counters().lost_attempts, 1);
}

TEST(SimulationFleet, FailsADrapeWhenOnlyWorkersThatDoNotComputeAreLeft) {
  FleetOptions o = fast_options();
  o.wait_s = 0.5;
  auto fleet = SimulationFleet::start(o);
  ASSERT_TRUE(fleet);
  IgnoringWorker ignoring((*fleet)->endpoint());
  ASSERT_EQ((*fleet)->wait_for_workers(1, 20.0), 1);
  auto drape = (*fleet)->simulate(small_drape(6));
  ASSERT_FALSE(drape);
  EXPECT_NE(drape.error().message.find("no worker that computes drapes connected"), std::string::npos)
      << drape.error().message;
}

TEST(SimulationFleet, AdmitsOnlyAuthorisedWorkersAndNeedsCurveBeyondLoopback) {
  FleetOptions open = fast_options();
  open.bind = "tcp://0.0.0.0:*";
  auto refused = SimulationFleet::start(open);
  ASSERT_FALSE(refused);
  EXPECT_NE(refused.error().message.find("without authentication"), std::string::npos) << refused.error().message;

  const auto dir = std::filesystem::temp_directory_path() / ("drapegen-fleet-keys-" + std::to_string(::getpid()));
  std::filesystem::create_directories(dir);
  for (const char* name : {"server", "good", "stranger"}) {
    auto pair = make_curve_keypair();
    ASSERT_TRUE(pair) << pair.error().message;
    ASSERT_TRUE(write_curve_keypair(*pair, (dir / name).string()));
  }
  std::filesystem::copy_file(dir / "good.pub", dir / "authorized");
  FleetOptions curve = fast_options();
  curve.bind = "tcp://0.0.0.0:*";
  curve.server_secret_key = (dir / "server.key").string();
  curve.authorized_keys = (dir / "authorized").string();
  auto fleet = SimulationFleet::start(curve);
  ASSERT_TRUE(fleet) << fleet.error().message;
  const std::string port = (*fleet)->endpoint().substr((*fleet)->endpoint().rfind(':'));
  const std::string endpoint = "tcp://127.0.0.1" + port;
  {
    Workers stranger(endpoint, 1, {(dir / "server.pub").string(), (dir / "stranger.key").string()});
    EXPECT_EQ((*fleet)->wait_for_workers(1, 1.0), 0);  // its handshake is refused
  }
  Workers good(endpoint, 1, {(dir / "server.pub").string(), (dir / "good.key").string()});
  auto drape = (*fleet)->simulate(small_drape(2));
  ASSERT_TRUE(drape) << drape.error().message;
  EXPECT_EQ(drape->mesh.positions, sim::simulate_drape(small_drape(2))->mesh.positions);
  EXPECT_EQ((*fleet)->counters().workers_seen, 1);  // the stranger never registered
  std::filesystem::remove_all(dir);
}

}  // namespace
}  // namespace drapegen::coordinator
