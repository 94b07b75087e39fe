// Acceptance 4: random bytes, truncated frames, wrong protocol versions, and results for unknown or finished jobs
// sent to the coordinator's port leave it running and the manifest unchanged.
#include <arpa/inet.h>
#include <cmath>
#include <functional>
#include <netinet/in.h>
#include <random>
#include <sys/socket.h>
#include <unistd.h>
#include <zmq.hpp>

#include "drapegen/proto/codec.hpp"
#include "service_harness.hpp"

namespace drapegen::test {
namespace {
namespace v1 = proto::v1;

/// Everything the manifest records, as text.
std::string dump(const fs::path& manifest) {
  auto reader = storage::ManifestReader::open(manifest.string());
  if (!reader) return "unreadable: " + reader.error().message;
  std::ostringstream s;
  for (const auto& j : all(reader->jobs())) {
    s << "job " << j.id << " " << storage::to_string(j.state) << " " << j.attempts << " " << j.worker << " "
      << j.failure_reason << " " << j.recipe_json << "\n";
  }
  for (const auto& r : all(reader->results())) s << "result " << r.job_id << " " << r.outcome << "\n";
  for (const auto& f : all(reader->files())) s << "file " << f.path << " " << f.sha256 << "\n";
  for (const auto& f : all(reader->failures()))
    s << "failure " << f.job_id << " " << f.attempt << " " << f.reason << "\n";
  return s.str();
}

/// A hand-driven worker: a DEALER socket speaking (or abusing) the protocol.
class FakeWorker {
 public:
  FakeWorker(zmq::context_t& context, const std::string& endpoint) : socket_(context, zmq::socket_type::dealer) {
    socket_.set(zmq::sockopt::linger, 0);
    socket_.connect(endpoint);
  }
  void send_raw(const std::string& bytes) { socket_.send(zmq::buffer(bytes), zmq::send_flags::none); }
  void send(v1::Envelope e) { send_raw(proto::encode(std::move(e))); }
  void send_frames(const std::vector<std::string>& frames) {
    for (std::size_t i = 0; i < frames.size(); ++i) {
      socket_.send(zmq::buffer(frames[i]), i + 1 < frames.size() ? zmq::send_flags::sndmore : zmq::send_flags::none);
    }
  }
  /// The next envelope of the given kind (heartbeats skipped), or none within the timeout.
  std::optional<v1::Envelope> expect(v1::Envelope::BodyCase kind, std::chrono::milliseconds timeout) {
    const auto until = std::chrono::steady_clock::now() + timeout;
    while (std::chrono::steady_clock::now() < until) {
      zmq::pollitem_t item{socket_.handle(), 0, ZMQ_POLLIN, 0};
      zmq::poll(&item, 1, std::chrono::milliseconds(20));
      zmq::message_t frame;
      while (socket_.recv(frame, zmq::recv_flags::dontwait)) {
        auto e = proto::decode(frame.data(), frame.size());
        if (e && e->body_case() == kind) return *e;
      }
    }
    return std::nullopt;
  }
  /// A heartbeat naming the job being computed (0: idle), as a worker sends it.
  void heartbeat(std::uint64_t job = 0) {
    v1::Envelope e;
    e.mutable_heartbeat()->set_job_id(job);
    e.mutable_heartbeat()->set_interval_ms(10000);
    send(std::move(e));
  }

 private:
  zmq::socket_t socket_;
};

v1::Envelope ready(const std::string& name) {
  v1::Envelope e;
  e.mutable_ready()->set_worker_name(name);
  e.mutable_ready()->set_interval_ms(10000);  // a slow heartbeat: the test pauses between messages
  return e;
}

v1::Envelope result(std::uint64_t job, std::uint32_t attempt) {
  v1::Envelope e;
  e.mutable_result()->set_job_id(job);
  e.mutable_result()->set_attempt(attempt);
  e.mutable_result()->mutable_metrics()->set_outcome("noop");
  return e;
}

v1::Envelope failure(std::uint64_t job, std::uint32_t attempt) {
  v1::Envelope e;
  e.mutable_failure()->set_job_id(job);
  e.mutable_failure()->set_attempt(attempt);
  e.mutable_failure()->set_reason(v1::FAILURE_REASON_DIVERGED);
  e.mutable_failure()->set_message("forged");
  return e;
}

/// Raw TCP: connect, write `bytes`, close (no ZMTP handshake, or a broken one).
void raw_tcp(int port, const std::string& bytes) {
  const int fd = ::socket(AF_INET, SOCK_STREAM, 0);
  sockaddr_in addr{};
  addr.sin_family = AF_INET;
  addr.sin_port = htons(static_cast<std::uint16_t>(port));
  addr.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
  if (::connect(fd, reinterpret_cast<sockaddr*>(&addr), sizeof addr) == 0) {
    (void)!::write(fd, bytes.data(), bytes.size());
    std::this_thread::sleep_for(5ms);
  }
  ::close(fd);
}

TEST(Service, BadInputLeavesTheCoordinatorRunningAndTheManifestUnchanged) {
  const fs::path dir = test_dir("bad_input");
  const fs::path out = dir / "run";
  // No-op jobs: the fake worker can complete one legitimately.
  write_text(dir / "run.toml", small_config(out, 3, 2, "[testing]\nmode = \"noop\"\n"));
  Process coordinator({"run", "--config", (dir / "run.toml").string()}, (dir / "coordinator").string());
  const std::string endpoint = wait_endpoint(out, coordinator, 30s);
  ASSERT_FALSE(endpoint.empty()) << coordinator.err();
  const fs::path manifest = out / "manifest.sqlite";
  const int port = std::stoi(endpoint.substr(endpoint.rfind(':') + 1));

  zmq::context_t context(1);
  FakeWorker a(context, endpoint);
  a.send(ready("fake-a"));
  auto job1 = a.expect(v1::Envelope::kJob, 5s);
  ASSERT_TRUE(job1);
  const std::uint64_t first = job1->job().job_id();
  a.send(result(first, job1->job().attempt()));  // a legitimate result
  auto job2 = a.expect(v1::Envelope::kJob, 5s);  // and the next lease
  ASSERT_TRUE(job2);
  const std::uint64_t second = job2->job().job_id();
  const auto until = std::chrono::steady_clock::now() + 10s;
  while (recorded_jobs(manifest) < 1 && std::chrono::steady_clock::now() < until) std::this_thread::sleep_for(10ms);
  ASSERT_EQ(recorded_jobs(manifest), 1);
  const std::string before = dump(manifest);

  std::mt19937_64 rng(3);
  auto random_bytes = [&](std::size_t n) {
    std::string s(n, '\0');
    for (auto& c : s) c = static_cast<char>(rng());
    return s;
  };
  FakeWorker b(context, endpoint);  // never registers
  for (int round = 0; round < 3; ++round) {
    // Random bytes and truncated frames on the protocol.
    for (int i = 0; i < 50; ++i) {
      a.send_raw(random_bytes(rng() % 200));
      b.send_raw(random_bytes(rng() % 200));
    }
    const std::string valid = proto::encode(result(second, job2->job().attempt()));
    for (std::size_t n = 0; n < valid.size(); ++n) b.send_raw(valid.substr(0, n));
    for (std::size_t n = 0; n + 1 < valid.size(); ++n) a.send_raw(valid.substr(0, n));
    // Wrong protocol versions.
    for (std::uint32_t version : {0u, 2u, 99u}) {
      v1::Envelope e = result(second, job2->job().attempt());
      e.set_protocol_version(version);
      std::string bytes;
      e.SerializeToString(&bytes);
      a.send_raw(bytes);
      b.send_raw(bytes);
    }
    // Several frames, empty frames.
    a.send_frames({proto::encode(result(second, 1)), "x"});
    a.send_raw("");
    // Results and failures for finished, unknown and not-held jobs, and for a wrong attempt.
    a.send(result(first, job1->job().attempt()));
    a.send(failure(first, job1->job().attempt()));
    a.send(result(999, 1));
    a.send(failure(999, 1));
    a.send(result(second, job2->job().attempt() + 1));
    for (std::uint64_t other = 1; other <= 6; ++other) {
      if (other != first && other != second) a.send(result(other, 1));
    }
    b.send(result(second, job2->job().attempt()));  // unregistered peer
    b.send(failure(first, 1));
    // Raw TCP: garbage instead of a ZMTP greeting, a truncated greeting.
    raw_tcp(port, random_bytes(64));
    raw_tcp(port, std::string("\xff\0\0\0\0\0\0\0\x01\x7f\x03", 11));
    raw_tcp(port, "");
    a.heartbeat();
    std::this_thread::sleep_for(100ms);
  }
  // The unregistered peer is told to register.
  EXPECT_TRUE(b.expect(v1::Envelope::kDisconnect, 2s));
  std::this_thread::sleep_for(300ms);
  ASSERT_TRUE(coordinator.running()) << coordinator.err();
  EXPECT_EQ(dump(manifest), before);
  EXPECT_NE(coordinator.err().find("dropped a message"), std::string::npos);

  // The coordinator still works: the fake finishes its lease, a real worker does the rest.
  a.send(result(second, job2->job().attempt()));
  Process worker = start_worker(endpoint, dir, 1);
  // The fake keeps answering whatever it gets until the run ends.
  const auto end = std::chrono::steady_clock::now() + 30s;
  while (coordinator.running() && std::chrono::steady_clock::now() < end) {
    if (auto job = a.expect(v1::Envelope::kJob, 50ms)) a.send(result(job->job().job_id(), job->job().attempt()));
    a.heartbeat();
  }
  ASSERT_EQ(coordinator.wait(10s), 0) << coordinator.err();
  check_manifest(manifest, 2);
  auto reader = storage::ManifestReader::open(manifest.string());
  ASSERT_TRUE(reader);
  EXPECT_EQ(reader->results()->size(), 6u);
  EXPECT_TRUE(reader->failures()->empty());
}

// Leases: a worker that keeps heartbeating but never answers loses its lease after network.lease_s (a `timeout`
// failure, the job re-queued and done by another worker); its late answer is dropped.
TEST(Service, ExpiredLeasesAreRequeued) {
  const fs::path dir = test_dir("lease");
  const fs::path out = dir / "run";
  // The lease goes into small_config's [network] table.
  std::string text = small_config(out, 2, 1, "[testing]\nmode = \"noop\"\n[retry]\nmax_attempts = 3\n");
  text.replace(text.find("liveness = 4\n"), 13, "liveness = 4\nlease_s = 0.5\n");
  write_text(dir / "run.toml", text);
  const fs::path manifest = out / "manifest.sqlite";
  Process coordinator({"run", "--config", (dir / "run.toml").string()}, (dir / "coordinator").string());
  const std::string endpoint = wait_endpoint(out, coordinator, 30s);
  ASSERT_FALSE(endpoint.empty()) << coordinator.err();

  zmq::context_t context(1);
  FakeWorker slow(context, endpoint);
  slow.send(ready("slow"));
  auto job = slow.expect(v1::Envelope::kJob, 5s);
  ASSERT_TRUE(job);
  const std::uint64_t id = job->job().job_id();
  // Alive, still computing the job for 1.5 s (three leases).
  for (int i = 0; i < 15; ++i) {
    slow.heartbeat(id);
    std::this_thread::sleep_for(100ms);
  }
  slow.send(result(id, job->job().attempt()));  // too late: dropped
  Process worker = start_worker(endpoint, dir, 1);
  const auto end = std::chrono::steady_clock::now() + 30s;
  while (coordinator.running() && std::chrono::steady_clock::now() < end) {
    if (auto next = slow.expect(v1::Envelope::kJob, 50ms)) {
      slow.send(result(next->job().job_id(), next->job().attempt()));
    }
    slow.heartbeat();
  }
  ASSERT_EQ(coordinator.wait(10s), 0) << coordinator.err();
  check_manifest(manifest, 2);
  auto reader = storage::ManifestReader::open(manifest.string());
  ASSERT_TRUE(reader);
  const auto failures = all(reader->failures());
  ASSERT_GE(failures.size(), 1u);
  EXPECT_EQ(failures[0].job_id, static_cast<std::int64_t>(id));
  EXPECT_EQ(failures[0].attempt, 1);
  EXPECT_EQ(failures[0].reason, "timeout");
  EXPECT_EQ(failures[0].worker, "slow");
  for (const auto& j : all(reader->jobs())) {
    EXPECT_EQ(j.state, storage::JobState::kDone);
    if (j.id == static_cast<std::int64_t>(id)) {
      EXPECT_GE(j.attempts, 2);
    }
  }
  EXPECT_NE(coordinator.err().find("after its lease expired"), std::string::npos) << coordinator.err();
}

// A worker whose answer never arrived (lost, or dropped by the coordinator's checks) and whose lease then expired
// says it is idle in its heartbeats: it is free for the next job. Before, it stayed marked as computing the expired
// job for the rest of the run, heartbeating and idle.
TEST(Service, AWorkerWhoseAnswerNeverCameIsFreeOnceIdle) {
  const fs::path dir = test_dir("lost_answer");
  const fs::path out = dir / "run";
  std::string text = small_config(out, 2, 1, "[testing]\nmode = \"noop\"\n[retry]\nmax_attempts = 3\n");
  text.replace(text.find("liveness = 4\n"), 13, "liveness = 4\nlease_s = 0.5\n");
  write_text(dir / "run.toml", text);
  Process coordinator({"run", "--config", (dir / "run.toml").string()}, (dir / "coordinator").string());
  const std::string endpoint = wait_endpoint(out, coordinator, 30s);
  ASSERT_FALSE(endpoint.empty()) << coordinator.err();
  zmq::context_t context(1);
  FakeWorker w(context, endpoint);
  w.send(ready("w"));
  auto first = w.expect(v1::Envelope::kJob, 5s);
  ASSERT_TRUE(first);
  for (int i = 0; i < 10; ++i) {  // computing it past its lease (0.5 s)
    w.heartbeat(first->job().job_id());
    std::this_thread::sleep_for(100ms);
  }
  w.heartbeat();  // done, but its answer never arrived
  auto next = w.expect(v1::Envelope::kJob, 5s);
  ASSERT_TRUE(next) << "an idle worker was left without work: " << coordinator.err();
  w.send(result(next->job().job_id(), next->job().attempt()));
  auto last = w.expect(v1::Envelope::kJob, 5s);
  ASSERT_TRUE(last) << coordinator.err();
  w.send(result(last->job().job_id(), last->job().attempt()));
  ASSERT_EQ(coordinator.wait(30s), 0) << coordinator.err();
  EXPECT_NE(coordinator.err().find("is idle without having answered job"), std::string::npos) << coordinator.err();
}

// A retry goes to another worker while there is one: the worker that failed a job is freed first and took the retry
// straight back, so a worker with a full scratch directory spent every attempt of each job it was given.
TEST(Service, ARetryGoesToAnotherWorker) {
  const fs::path dir = test_dir("retry_elsewhere");
  const fs::path out = dir / "run";
  write_text(dir / "run.toml", small_config(out, 2, 1, "[testing]\nmode = \"noop\"\n[retry]\nmax_attempts = 3\n"));
  Process coordinator({"run", "--config", (dir / "run.toml").string()}, (dir / "coordinator").string());
  const std::string endpoint = wait_endpoint(out, coordinator, 30s);
  ASSERT_FALSE(endpoint.empty()) << coordinator.err();
  zmq::context_t context(1);
  FakeWorker a(context, endpoint), b(context, endpoint);
  a.send(ready("a"));
  auto a1 = a.expect(v1::Envelope::kJob, 5s);
  ASSERT_TRUE(a1);
  b.send(ready("b"));
  auto b1 = b.expect(v1::Envelope::kJob, 5s);
  ASSERT_TRUE(b1);
  ASSERT_NE(a1->job().job_id(), b1->job().job_id());
  a.send(failure(a1->job().job_id(), 1));
  EXPECT_FALSE(a.expect(v1::Envelope::kJob, 1s)) << "the job a failed went back to a while b is connected";
  b.send(failure(b1->job().job_id(), 1));
  auto a2 = a.expect(v1::Envelope::kJob, 5s);
  auto b2 = b.expect(v1::Envelope::kJob, 5s);
  ASSERT_TRUE(a2 && b2) << coordinator.err();
  EXPECT_EQ(a2->job().job_id(), b1->job().job_id());
  EXPECT_EQ(b2->job().job_id(), a1->job().job_id());
  EXPECT_EQ(a2->job().attempt(), 2u);
  a.send(result(a2->job().job_id(), 2));
  b.send(result(b2->job().job_id(), 2));
  ASSERT_EQ(coordinator.wait(60s), 0) << coordinator.err();
  auto reader = storage::ManifestReader::open((out / "manifest.sqlite").string());
  ASSERT_TRUE(reader);
  const auto failures = all(reader->failures());
  ASSERT_EQ(failures.size(), 2u);
  for (const auto& j : all(reader->jobs())) EXPECT_EQ(j.state, storage::JobState::kDone);
}

/// A fake worker "old" takes the run's first job and sends `answer(job)`, which the coordinator must record as a
/// failed attempt of `reason` (no files kept); a real worker then does the job. Returns the failures.
std::vector<storage::FailureRecord> failed_then_done(const std::string& name, const std::string& extra,
                                                     const std::function<v1::Envelope(const v1::Job&)>& answer,
                                                     const std::string& reason) {
  const fs::path dir = test_dir(name);
  const fs::path out = dir / "run";
  // Attempts to spare: the retry may be leased back to the old worker before it goes away.
  write_text(dir / "run.toml", small_config(out, 1, 1, extra + "[retry]\nmax_attempts = 5\n"));
  const fs::path manifest = out / "manifest.sqlite";
  Process coordinator({"run", "--config", (dir / "run.toml").string()}, (dir / "coordinator").string());
  const std::string endpoint = wait_endpoint(out, coordinator, 30s);
  EXPECT_FALSE(endpoint.empty()) << coordinator.err();
  if (endpoint.empty()) return {};
  zmq::context_t context(1);
  {
    FakeWorker old(context, endpoint);
    v1::Envelope hello = ready("old");
    // Lost 2 s after it goes silent (it may be leased the retry): long enough to answer on a busy machine.
    hello.mutable_ready()->set_interval_ms(500);
    old.send(hello);
    auto job = old.expect(v1::Envelope::kJob, 5s);
    EXPECT_TRUE(job);
    if (!job) return {};
    old.send(answer(job->job()));
    const auto recorded = [&] {
      auto r = storage::ManifestReader::open(manifest.string());
      if (!r) return false;
      auto f = r->failures();
      return f && !f->empty() && f->front().reason == reason;
    };
    const auto until = std::chrono::steady_clock::now() + 10s;
    while (!recorded() && std::chrono::steady_clock::now() < until) std::this_thread::sleep_for(10ms);
    EXPECT_TRUE(recorded()) << coordinator.err();
  }  // the old worker goes away
  Process worker = start_worker(endpoint, dir, 1);
  EXPECT_EQ(coordinator.wait(120s), 0) << coordinator.err();
  check_manifest(manifest, 2);
  auto reader = storage::ManifestReader::open(manifest.string());
  EXPECT_TRUE(reader);
  if (!reader) return {};
  for (const auto& j : all(reader->jobs())) EXPECT_EQ(j.state, storage::JobState::kDone);
  EXPECT_EQ(all(reader->results()).size(), 1u);
  auto failures = all(reader->failures());
  EXPECT_GE(failures.size(), 1u);
  if (!failures.empty()) {
    EXPECT_EQ(failures[0].reason, reason);
    EXPECT_EQ(failures[0].worker, "old");
  }
  return failures;
}

/// A complete result for `job` (mesh, one EXR per orientation, the job's bending model) that `spoil` then edits.
std::function<v1::Envelope(const v1::Job&)> spoiled_result(const std::function<void(v1::Result&)>& spoil) {
  return [spoil](const v1::Job& job) {
    v1::Envelope e = result(job.job_id(), job.attempt());
    e.mutable_result()->mutable_metrics()->set_outcome("converged");
    e.mutable_result()->mutable_metrics()->set_bending_model(job.spec().bending_model());
    e.mutable_result()->mutable_metrics()->set_renderer(job.spec().renderer());
    e.mutable_result()->set_mesh_ply("ply");
    for (int k = 0; k < 2; ++k) e.mutable_result()->add_exr("exr");
    spoil(*e.mutable_result());
    return e;
  };
}

// A worker older than the bending-model field drapes with the paper's model whatever the run asks, and says nothing
// about it: the coordinator refuses its result (an invalid_job failure, no files kept) and another worker does the job.
TEST(Service, ResultOfAnotherBendingModelIsRefused) {
  const auto failures = failed_then_done(
      "model_mismatch", "bending_model = \"triangle\"\n",
      spoiled_result([](v1::Result& r) { r.mutable_metrics()->clear_bending_model(); }), "invalid_job");
  ASSERT_FALSE(failures.empty());
  EXPECT_NE(failures[0].message.find("dihedral (unnamed)"), std::string::npos) << failures[0].message;
  EXPECT_NE(failures[0].message.find("triangle"), std::string::npos) << failures[0].message;
}

// Likewise a worker older than the renderer field renders with OSMesa whatever the run asks.
TEST(Service, ResultOfAnotherRendererIsRefused) {
  const auto failures = failed_then_done(
      "renderer_mismatch", "renderer = \"software\"\n",
      spoiled_result([](v1::Result& r) { r.mutable_metrics()->clear_renderer(); }), "invalid_job");
  ASSERT_FALSE(failures.empty());
  EXPECT_NE(failures[0].message.find("rendered the views with osmesa (unnamed), the run asks for software"),
            std::string::npos)
      << failures[0].message;
}

// A result with one file per orientation but an empty one among them would be recorded, checksum and all, and fail
// the training stage's reader later: it is an incomplete result (render_error) like one with a file missing.
TEST(Service, AResultWithAnEmptyFileIsRefused) {
  const auto failures = failed_then_done(
      "empty_exr", "", spoiled_result([](v1::Result& r) { r.mutable_exr(1)->clear(); }), "render_error");
  ASSERT_FALSE(failures.empty());
  EXPECT_NE(failures[0].message.find("EXR file 2 of 2 is empty"), std::string::npos) << failures[0].message;
}

// A failure whose reason this coordinator does not know (a newer worker's) is recorded as "unspecified" with its
// number; the codec's check dropped it before (the job waited out its lease), and the manifest's check on reasons
// refused "unspecified", which stopped the whole run.
TEST(Service, AFailureOfAnUnknownReasonIsRecordedNotFatal) {
  const auto failures = failed_then_done(
      "unknown_reason", "",
      [](const v1::Job& job) {
        v1::Envelope e;
        e.mutable_failure()->set_job_id(job.job_id());
        e.mutable_failure()->set_attempt(job.attempt());
        e.mutable_failure()->set_reason(static_cast<v1::FailureReason>(42));
        e.mutable_failure()->set_message("a reason from a later release");
        return e;
      },
      "unspecified");
  ASSERT_FALSE(failures.empty());
  EXPECT_EQ(failures[0].message, "(reason 42) a reason from a later release");
}

// A result whose metrics are not finite (SQLite would store NaN as NULL in a NOT NULL column) is a failed attempt
// with its reason, not a storage error that stops the run; the job is retried and the run completes.
TEST(Service, ANonFiniteResultIsAFailedAttempt) {
  const fs::path dir = test_dir("non_finite_result");
  const fs::path out = dir / "run";
  write_text(dir / "run.toml", small_config(out, 1, 1, "[testing]\nmode = \"noop\"\n[retry]\nmax_attempts = 3\n"));
  const fs::path manifest = out / "manifest.sqlite";
  Process coordinator({"run", "--config", (dir / "run.toml").string()}, (dir / "coordinator").string());
  const std::string endpoint = wait_endpoint(out, coordinator, 30s);
  ASSERT_FALSE(endpoint.empty()) << coordinator.err();
  zmq::context_t context(1);
  FakeWorker a(context, endpoint);
  a.send(ready("nan"));
  auto job = a.expect(v1::Envelope::kJob, 5s);
  ASSERT_TRUE(job);
  v1::Envelope bad = result(job->job().job_id(), job->job().attempt());
  bad.mutable_result()->mutable_metrics()->set_residual(std::nan(""));
  a.send(bad);
  // The retry comes back to the only worker: answered properly, the run completes.
  auto retry = a.expect(v1::Envelope::kJob, 5s);
  ASSERT_TRUE(retry) << coordinator.err();
  EXPECT_EQ(retry->job().job_id(), job->job().job_id());
  EXPECT_EQ(retry->job().attempt(), job->job().attempt() + 1);
  a.send(result(retry->job().job_id(), retry->job().attempt()));
  ASSERT_EQ(coordinator.wait(10s), 0) << coordinator.err();
  auto reader = storage::ManifestReader::open(manifest.string());
  ASSERT_TRUE(reader);
  const auto failures = all(reader->failures());
  ASSERT_EQ(failures.size(), 1u);
  EXPECT_EQ(failures[0].reason, "diverged");
  EXPECT_EQ(failures[0].worker, "nan");
  EXPECT_NE(failures[0].message.find("non-finite residual"), std::string::npos) << failures[0].message;
  EXPECT_EQ(all(reader->results()).size(), 1u);
  for (const auto& j : all(reader->jobs())) EXPECT_EQ(j.state, storage::JobState::kDone);
}

// A worker of another build or with other BLAS kernels is served, with a warning naming both (worker.proto: Ready).
TEST(Service, AWorkerOfAnotherVersionOrOtherBlasKernelsIsWarnedAbout) {
  const fs::path dir = test_dir("other_version");
  const fs::path out = dir / "run";
  write_text(dir / "run.toml", small_config(out, 1, 1, "[testing]\nmode = \"noop\"\n"));
  Process coordinator({"run", "--config", (dir / "run.toml").string()}, (dir / "coordinator").string());
  const std::string endpoint = wait_endpoint(out, coordinator, 30s);
  ASSERT_FALSE(endpoint.empty()) << coordinator.err();
  zmq::context_t context(1);
  FakeWorker a(context, endpoint);
  v1::Envelope hello = ready("older");
  hello.mutable_ready()->set_code_version("0.0.1-test");
  hello.mutable_ready()->set_blas_kernels("OpenBLAS Test");
  a.send(hello);
  auto job = a.expect(v1::Envelope::kJob, 5s);
  ASSERT_TRUE(job) << coordinator.err();
  a.send(result(job->job().job_id(), job->job().attempt()));
  ASSERT_EQ(coordinator.wait(10s), 0) << coordinator.err();
  EXPECT_NE(coordinator.err().find("worker older runs drapegen 0.0.1-test, this coordinator "), std::string::npos)
      << coordinator.err();
  EXPECT_NE(coordinator.err().find("worker older factorises with OpenBLAS Test, this coordinator with "),
            std::string::npos)
      << coordinator.err();
}

// Jobs that failed for a cause outside them (here a broken worker: every attempt of one attempt each fails) are
// retried by `--resume --retry-failed` with retry.max_attempts more attempts each: they complete on a healthy worker,
// their failures stay recorded and their attempt numbers go on. Without --resume the flag is refused.
TEST(Service, RetryFailedGivesFailedJobsMoreAttemptsOnResume) {
  const fs::path dir = test_dir("retry_failed");
  const fs::path out = dir / "run";
  const fs::path manifest = out / "manifest.sqlite";
  write_text(dir / "run.toml", small_config(out, 3, 1, "[retry]\nmax_attempts = 1\n"));
  Process refused({"run", "--config", (dir / "run.toml").string(), "--retry-failed"}, (dir / "refused").string());
  EXPECT_NE(refused.wait(30s), 0);
  EXPECT_NE(refused.err().find("--retry-failed requires --resume"), std::string::npos) << refused.err();
  EXPECT_FALSE(fs::exists(manifest));

  auto [coordinator, endpoint] = start_coordinator({"--config", (dir / "run.toml").string()}, out, dir / "first");
  ASSERT_FALSE(endpoint.empty()) << coordinator.err();
  zmq::context_t context;
  FakeWorker broken(context, endpoint);
  broken.send(ready("broken"));
  for (int k = 0; k < 3; ++k) {
    auto job = broken.expect(v1::Envelope::kJob, 30s);
    ASSERT_TRUE(job) << coordinator.err();
    broken.send(failure(job->job().job_id(), job->job().attempt()));
  }
  ASSERT_EQ(coordinator.wait(30s), 0) << coordinator.err();  // complete: every job failed
  {
    auto reader = storage::ManifestReader::open(manifest.string());
    ASSERT_TRUE(reader);
    for (const auto& j : all(reader->jobs())) EXPECT_EQ(j.state, storage::JobState::kFailed) << j.id;
  }

  auto [resumed, resumed_endpoint] =
      start_coordinator({"--resume", manifest.string(), "--retry-failed"}, out, dir / "resumed");
  ASSERT_FALSE(resumed_endpoint.empty()) << resumed.err();
  Process worker = start_worker(resumed_endpoint, dir, 1);
  ASSERT_EQ(resumed.wait(120s), 0) << resumed.err();
  EXPECT_NE(resumed.err().find("3 failed job(s) pending again, 1 more attempt(s) each"), std::string::npos)
      << resumed.err();
  check_manifest(manifest, 2);
  auto reader = storage::ManifestReader::open(manifest.string());
  ASSERT_TRUE(reader);
  for (const auto& j : all(reader->jobs())) {
    EXPECT_EQ(j.state, storage::JobState::kDone) << j.id;
    EXPECT_EQ(j.attempts, 2) << j.id;
    EXPECT_EQ(j.failure_reason, "") << j.id;
  }
  const auto failures = all(reader->failures());
  ASSERT_EQ(failures.size(), 3u);
  for (const auto& f : failures) EXPECT_EQ(f.attempt, 1) << f.job_id;
}

// The retried job's extra attempts survive a resume: max_attempts 3, failed at 3; retried, failed at 4 and stopped;
// resumed without the flag it still has attempts 5 and 6 (it had max_attempts only, 3, and failed at 5 before).
TEST(Service, ARetriedJobKeepsItsExtraAttemptsAcrossAResume) {
  const fs::path dir = test_dir("retry_budget");
  const fs::path out = dir / "run";
  const fs::path manifest = out / "manifest.sqlite";
  write_text(dir / "run.toml", small_config(out, 1, 1, "[retry]\nmax_attempts = 3\n"));
  zmq::context_t context;
  // A session served by a worker that fails `fails` attempts; then the run is stopped (SIGTERM), or ends with the job
  // failed (3 failures), or a real worker completes it.
  const auto session = [&](const std::vector<std::string>& args, const std::string& name, int fails, bool stop) {
    auto [coordinator, endpoint] = start_coordinator(args, out, dir / name);
    ASSERT_FALSE(endpoint.empty()) << coordinator.err();
    FakeWorker broken(context, endpoint);
    broken.send(ready("broken"));
    for (int k = 0; k < fails; ++k) {
      auto job = broken.expect(v1::Envelope::kJob, 30s);
      ASSERT_TRUE(job) << coordinator.err();
      broken.send(failure(job->job().job_id(), job->job().attempt()));
    }
    if (stop) {
      const auto until = std::chrono::steady_clock::now() + 10s;  // the last failure recorded, then stop
      while (std::chrono::steady_clock::now() < until) {
        auto reader = storage::ManifestReader::open(manifest.string());
        if (reader && reader->failures() && static_cast<int>(reader->failures()->size()) >= 4) break;
        std::this_thread::sleep_for(20ms);
      }
      ::kill(coordinator.pid(), SIGTERM);
      ASSERT_EQ(coordinator.wait(30s), 4) << coordinator.err();
      return;
    }
    if (fails == 3) {
      ASSERT_EQ(coordinator.wait(30s), 0) << coordinator.err();  // the job failed: the run is complete
      return;
    }
    v1::Envelope leave;  // the broken worker goes (else the job, failed by it, is leased to it again: no other)
    leave.mutable_leave()->set_reason("test");
    broken.send(leave);
    Process worker = start_worker(endpoint, dir, 1);
    ASSERT_EQ(coordinator.wait(120s), 0) << coordinator.err();
  };
  session({"--config", (dir / "run.toml").string()}, "first", 3, false);
  session({"--resume", manifest.string(), "--retry-failed"}, "retried", 1, true);
  session({"--resume", manifest.string()}, "resumed", 1, false);
  auto reader = storage::ManifestReader::open(manifest.string());
  ASSERT_TRUE(reader);
  const auto jobs = all(reader->jobs());
  ASSERT_EQ(jobs.size(), 1u);
  EXPECT_EQ(jobs[0].state, storage::JobState::kDone);
  EXPECT_EQ(jobs[0].attempts, 6);
  EXPECT_EQ(all(reader->failures()).size(), 5u);
}

// A worker that leaves (stopped) gives its job back without costing an attempt, but only three times per job: a job
// that outlasts every worker's time limit (a scheduler's --time shorter than the lease) would go round for ever. The
// fourth leave is a lost worker's failed attempt, and with one attempt per job the job fails.
TEST(Service, AJobIsForgivenThreeLeavesNotMore) {
  const fs::path dir = test_dir("leaves");
  const fs::path out = dir / "run";
  write_text(dir / "run.toml", small_config(out, 1, 1, "[retry]\nmax_attempts = 1\n"));
  auto [coordinator, endpoint] = start_coordinator({"--config", (dir / "run.toml").string()}, out, dir / "coordinator");
  ASSERT_FALSE(endpoint.empty()) << coordinator.err();
  zmq::context_t context;
  for (int k = 0; k < 4; ++k) {
    FakeWorker leaving(context, endpoint);
    leaving.send(ready("leaving" + std::to_string(k)));
    auto job = leaving.expect(v1::Envelope::kJob, 30s);
    ASSERT_TRUE(job) << k << ": " << coordinator.err();
    EXPECT_EQ(job->job().attempt(), 1u) << k;  // given back: the same attempt again
    v1::Envelope leave;
    leave.mutable_leave()->set_job_id(job->job().job_id());
    leave.mutable_leave()->set_attempt(job->job().attempt());
    leaving.send(leave);
  }
  ASSERT_EQ(coordinator.wait(30s), 0) << coordinator.err();  // the job failed: the run is complete
  auto reader = storage::ManifestReader::open((out / "manifest.sqlite").string());
  ASSERT_TRUE(reader);
  const auto failures = all(reader->failures());
  ASSERT_EQ(failures.size(), 1u);
  EXPECT_EQ(failures[0].reason, "worker_lost");
  EXPECT_NE(failures[0].message.find("stopped while computing it, again"), std::string::npos) << failures[0].message;
  EXPECT_EQ(all(reader->jobs())[0].state, storage::JobState::kFailed);
}

}  // namespace
}  // namespace drapegen::test
