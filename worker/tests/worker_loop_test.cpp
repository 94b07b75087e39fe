// The worker's connection loop against a stand-in coordinator (a ROUTER socket on 127.0.0.1): a job this build's
// checks refuse is answered as an invalid job at once, where it was dropped and its lease held until it expired.
#include <gtest/gtest.h>

#include <atomic>
#include <chrono>
#include <future>
#include <optional>
#include <string>
#include <vector>
#include <zmq.hpp>
#include <zmq_addon.hpp>

#include "drapegen/proto/codec.hpp"
#include "drapegen/worker/worker.hpp"

namespace drapegen::worker {
namespace {

namespace v1 = proto::v1;
using namespace std::chrono_literals;

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

void send(zmq::socket_t& router, const std::string& identity, v1::Envelope e) {
  const std::string frame = proto::encode(std::move(e));
  router.send(zmq::buffer(identity), zmq::send_flags::sndmore);
  router.send(zmq::buffer(frame), zmq::send_flags::none);
}

TEST(WorkerLoop, AJobItsChecksRefuseIsAnsweredAsAnInvalidJob) {
  zmq::context_t context;
  zmq::socket_t router(context, zmq::socket_type::router);
  router.bind("tcp://127.0.0.1:*");
  const std::string endpoint = router.get(zmq::sockopt::last_endpoint);
  std::atomic<bool> stop{false};
  WorkerOptions options;
  options.endpoint = endpoint;
  options.name = "loop-test";
  options.heartbeat_ms = 100;
  options.give_up_s = 30.0;
  auto worker = std::async(std::launch::async, [&] { return run_worker(options, stop); });

  auto ready = receive(router, 10s);
  ASSERT_TRUE(ready);
  ASSERT_EQ(ready->second.body_case(), v1::Envelope::kReady);
  const std::string identity = ready->first;

  v1::Envelope job;  // a resolution of 2: below every build's minimum, as a newer coordinator's new value would be
  job.mutable_job()->set_job_id(41);
  job.mutable_job()->set_attempt(2);
  job.mutable_job()->set_lease_ms(60000);
  job.mutable_job()->mutable_spec()->set_mode(v1::JOB_MODE_DRAPE);
  job.mutable_job()->mutable_spec()->set_resolution(2);
  send(router, identity, job);

  std::optional<v1::Failure> failure;
  const auto until = std::chrono::steady_clock::now() + 10s;
  while (!failure && std::chrono::steady_clock::now() < until) {
    auto message = receive(router, 1s);
    if (message && message->second.body_case() == v1::Envelope::kFailure) failure = message->second.failure();
  }
  ASSERT_TRUE(failure) << "no answer to the refused job";
  EXPECT_EQ(failure->job_id(), 41u);
  EXPECT_EQ(failure->attempt(), 2u);
  EXPECT_EQ(failure->reason(), v1::FAILURE_REASON_INVALID_JOB);
  EXPECT_NE(failure->message().find("the worker refused the job: "), std::string::npos) << failure->message();

  v1::Envelope shutdown;
  shutdown.mutable_shutdown()->set_reason("test over");
  send(router, identity, shutdown);
  ASSERT_EQ(worker.wait_for(10s), std::future_status::ready);
  const auto end = worker.get();
  ASSERT_TRUE(end) << end.error().message;
  EXPECT_EQ(*end, WorkerEnd::kRunOver);
}

}  // namespace
}  // namespace drapegen::worker
