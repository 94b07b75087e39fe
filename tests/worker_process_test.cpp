// A worker process against a stand-in coordinator (a ROUTER socket on 127.0.0.1). A job this build's checks refuse is
// answered as an invalid job at once, where it was dropped and its lease held until it expired. Stopped by SIGTERM
// mid-job (a scheduler's preemption), it leaves, naming the job it held, and exits with 4. Before, it said nothing
// (the coordinator found it lost by its silence and counted the attempt as failed), and a SIGTERM that came while
// METIS ordered the Hessian ran METIS's own handler on the wrong thread and crashed the worker (SIGSEGV).
#include <optional>
#include <vector>
#include <zmq.hpp>
#include <zmq_addon.hpp>

#include "drapegen/coordinator/job_message.hpp"
#include "drapegen/coordinator/planner.hpp"
#include "drapegen/coordinator/run_config.hpp"
#include "drapegen/proto/codec.hpp"
#include "service_harness.hpp"

namespace drapegen::test {
namespace {
namespace v1 = proto::v1;

/// The next message from a worker within `timeout`: its routing id and envelope.
std::optional<std::pair<std::string, v1::Envelope>> receive(zmq::socket_t& router, std::chrono::milliseconds timeout) {
  const auto until = std::chrono::steady_clock::now() + timeout;
  while (std::chrono::steady_clock::now() < until) {
    zmq::pollitem_t item{router.handle(), 0, ZMQ_POLLIN, 0};
    zmq::poll(&item, 1, 50ms);
    if (!(item.revents & ZMQ_POLLIN)) continue;
    std::vector<zmq::message_t> frames;
    if (!zmq::recv_multipart(router, std::back_inserter(frames)) || frames.size() != 2) continue;
    auto decoded = proto::decode(frames[1].data(), frames[1].size());
    if (decoded) return std::pair{frames[0].to_string(), std::move(*decoded)};
  }
  return std::nullopt;
}

/// The next message of `kind` from a worker within `timeout` (others skipped).
std::optional<v1::Envelope> receive_kind(zmq::socket_t& router, v1::Envelope::BodyCase kind,
                                         std::chrono::milliseconds timeout) {
  const auto until = std::chrono::steady_clock::now() + timeout;
  while (std::chrono::steady_clock::now() < until) {
    auto message = receive(router, 1s);
    if (message && message->second.body_case() == kind) return std::move(message->second);
  }
  return std::nullopt;
}

void send(zmq::socket_t& router, const std::string& identity, v1::Envelope e) {
  const std::string frame = proto::encode(std::move(e));
  router.send(zmq::buffer(identity), zmq::send_flags::sndmore);
  router.send(zmq::buffer(frame), zmq::send_flags::none);
}

/// A stand-in coordinator's ROUTER socket and a worker process registered with it.
class WorkerProcess : public ::testing::Test {
 protected:
  /// Starts the worker (logs in test_dir(name)); its routing id once it has sent Ready.
  void start(const std::string& name) {
    router_.set(zmq::sockopt::linger, 0);
    router_.bind("tcp://127.0.0.1:*");
    worker_ = start_worker(router_.get(zmq::sockopt::last_endpoint), test_dir(name), 0);
    auto ready = receive(router_, 30s);
    ASSERT_TRUE(ready) << worker_.err();
    ASSERT_EQ(ready->second.body_case(), v1::Envelope::kReady);
    identity_ = ready->first;
  }

  zmq::context_t context_;
  zmq::socket_t router_{context_, zmq::socket_type::router};
  Process worker_;
  std::string identity_;
};

TEST_F(WorkerProcess, AJobItsChecksRefuseIsAnsweredAsAnInvalidJob) {
  ASSERT_NO_FATAL_FAILURE(start("worker_refuses"));
  zmq::socket_t& router = router_;
  Process& worker = worker_;
  v1::Envelope job;  // a resolution of 2: below every build's minimum, as a newer coordinator's new value would be
  job.mutable_job()->set_job_id(41);
  job.mutable_job()->set_attempt(2);
  job.mutable_job()->set_lease_ms(60000);
  job.mutable_job()->mutable_spec()->set_mode(v1::JOB_MODE_DRAPE);
  job.mutable_job()->mutable_spec()->set_resolution(2);
  send(router, identity_, job);
  const auto answer = receive_kind(router, v1::Envelope::kFailure, 10s);
  ASSERT_TRUE(answer) << "no answer to the refused job: " << worker.err();
  const v1::Failure& failure = answer->failure();
  EXPECT_EQ(failure.job_id(), 41u);
  EXPECT_EQ(failure.attempt(), 2u);
  EXPECT_EQ(failure.reason(), v1::FAILURE_REASON_INVALID_JOB);
  EXPECT_NE(failure.message().find("the worker refused the job: "), std::string::npos) << failure.message();
  v1::Envelope shutdown;
  shutdown.mutable_shutdown()->set_reason("test over");
  send(router, identity_, shutdown);
  EXPECT_EQ(worker.wait(10s), 0) << worker.err();
}

TEST_F(WorkerProcess, StoppedMidJobItSaysWhichJobItLeaves) {
  auto config = coordinator::parse_run_config("samples = 1\nresolution = 61\norientations = 1", "run.toml");
  ASSERT_TRUE(config) << config.error().message;
  auto plan = coordinator::plan_run(*config);
  ASSERT_TRUE(plan) << plan.error().message;
  auto message = coordinator::make_job_message(*config, plan->samples.front(), plan->jobs.front(), 3, "");
  ASSERT_TRUE(message) << message.error().message;
  message->set_job_id(7);

  ASSERT_NO_FATAL_FAILURE(start("worker_stop"));
  zmq::socket_t& router = router_;
  Process& worker = worker_;
  v1::Envelope job;
  *job.mutable_job() = *message;
  send(router, identity_, job);

  // Computing: its heartbeat names the job (a 61x61 drape takes seconds).
  bool computing = false;
  const auto until = std::chrono::steady_clock::now() + 20s;
  while (!computing && std::chrono::steady_clock::now() < until) {
    auto m = receive(router, 1s);
    ASSERT_FALSE(m && (m->second.body_case() == v1::Envelope::kResult ||
                       m->second.body_case() == v1::Envelope::kFailure))
        << "the job ended before the test could stop it";
    computing = m && m->second.body_case() == v1::Envelope::kHeartbeat && m->second.heartbeat().job_id() == 7;
  }
  ASSERT_TRUE(computing) << worker.err();
  ::kill(worker.pid(), SIGTERM);
  const auto leave = receive_kind(router, v1::Envelope::kLeave, 10s);
  ASSERT_TRUE(leave) << "the stopped worker left without a word: " << worker.err();
  EXPECT_EQ(leave->leave().job_id(), 7u);
  EXPECT_EQ(leave->leave().attempt(), 3u);
  EXPECT_EQ(worker.wait(10s), 4) << worker.err();
}

}  // namespace
}  // namespace drapegen::test
