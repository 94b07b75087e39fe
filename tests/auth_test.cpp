// Acceptance 7: with CurveZMQ on (required on any non-loopback bind; forced here on 127.0.0.1 with
// [security] curve = true, since tests talk to loopback only), a worker without an authorised key gets no job and
// cannot submit a result; an authorised one completes the run.
#include <zmq.hpp>

#include "drapegen/proto/codec.hpp"
#include "service_harness.hpp"

namespace drapegen::test {
namespace {
namespace v1 = proto::v1;

std::string keygen(const fs::path& prefix, const fs::path& dir) {
  Process p({"keygen", "--out", prefix.string()}, (dir / ("keygen_" + prefix.filename().string())).string());
  EXPECT_EQ(p.wait(10s), 0) << p.err();
  // The secret is never readable by others, not even while it is written (created with that mode).
  EXPECT_EQ(fs::status(prefix.string() + ".key").permissions() & fs::perms::all,
            fs::perms::owner_read | fs::perms::owner_write);
  std::string pub = Process::slurp(prefix.string() + ".pub");
  if (!pub.empty() && pub.back() == '\n') pub.pop_back();
  return pub;
}

TEST(Service, CurveRefusesUnauthorisedWorkers) {
  const fs::path dir = test_dir("curve");
  const fs::path out = dir / "run";
  keygen(dir / "server", dir);
  const std::string good = keygen(dir / "good", dir);
  keygen(dir / "stranger", dir);
  write_text(dir / "authorized", "# workers allowed to take jobs\n" + good + "\n");
  write_text(dir / "run.toml",
             small_config(out, 2, 2,
                          "[security]\ncurve = true\nserver_secret_key = \"" + (dir / "server.key").string() +
                              "\"\nauthorized_keys = \"" + (dir / "authorized").string() +
                              "\"\n[testing]\nmode = \"noop\"\n"));
  const fs::path manifest = out / "manifest.sqlite";
  Process coordinator({"run", "--config", (dir / "run.toml").string()}, (dir / "coordinator").string());
  const std::string endpoint = wait_endpoint(out, coordinator, 30s);
  ASSERT_FALSE(endpoint.empty()) << coordinator.err();
  const std::string server_pub = (dir / "server.pub").string();

  // A worker with a key the coordinator does not know: the handshake is refused, it never hears anything.
  Process stranger({"worker", "--connect", endpoint, "--name", "stranger", "--server-key", server_pub, "--key",
                    (dir / "stranger.key").string(), "--heartbeat-ms", "100", "--liveness", "4", "--give-up", "2"},
                   (dir / "stranger").string());
  // A plain-TCP peer (no CURVE at all) sending ready and a forged result.
  zmq::context_t context(1);
  zmq::socket_t plain(context, zmq::socket_type::dealer);
  plain.set(zmq::sockopt::linger, 0);
  plain.connect(endpoint);
  v1::Envelope ready;
  ready.mutable_ready()->set_worker_name("plain");
  plain.send(zmq::buffer(proto::encode(ready)), zmq::send_flags::dontwait);
  v1::Envelope forged;
  forged.mutable_result()->set_job_id(1);
  forged.mutable_result()->set_attempt(1);
  forged.mutable_result()->mutable_metrics()->set_outcome("noop");
  plain.send(zmq::buffer(proto::encode(forged)), zmq::send_flags::dontwait);

  EXPECT_EQ(stranger.wait(30s), 1) << stranger.err();  // gave up: no coordinator ever answered
  EXPECT_NE(stranger.err().find("giving up"), std::string::npos) << stranger.err();
  zmq::pollitem_t item{plain.handle(), 0, ZMQ_POLLIN, 0};
  zmq::poll(&item, 1, std::chrono::milliseconds(200));
  EXPECT_FALSE(item.revents & ZMQ_POLLIN);  // the plain peer got nothing either
  ASSERT_TRUE(coordinator.running()) << coordinator.err();
  EXPECT_EQ(recorded_jobs(manifest), 0);
  EXPECT_EQ(coordinator.err().find("joined"), std::string::npos) << coordinator.err();
  EXPECT_NE(coordinator.err().find("refused a connection"), std::string::npos) << coordinator.err();

  // The authorised worker completes the run.
  Process worker({"worker", "--connect", endpoint, "--name", "good", "--server-key", server_pub, "--key",
                  (dir / "good.key").string(), "--heartbeat-ms", "100", "--liveness", "4", "--give-up", "30"},
                 (dir / "good").string());
  ASSERT_EQ(coordinator.wait(60s), 0) << coordinator.err();
  EXPECT_EQ(worker.wait(10s), 0) << worker.err();
  check_manifest(manifest, 2);
  auto reader = storage::ManifestReader::open(manifest.string());
  ASSERT_TRUE(reader);
  for (const auto& j : all(reader->jobs())) EXPECT_EQ(j.worker, "good");
  // Without keys the coordinator refuses a non-loopback bind.
  write_text(dir / "open.toml", small_config(dir / "open", 1, 1, "") );
  Process open({"run", "--config", (dir / "open.toml").string(), "--bind", "tcp://0.0.0.0:*"},
               (dir / "open").string());
  EXPECT_EQ(open.wait(30s), 1);
  EXPECT_NE(open.err().find("without authentication"), std::string::npos) << open.err();
  // curve = true with no keys in the file: refused without keys, served with them from the command line.
  write_text(dir / "cli_keys.toml",
             small_config(dir / "cli_keys", 1, 1, "[security]\ncurve = true\n[testing]\nmode = \"noop\"\n"));
  Process keyless({"run", "--config", (dir / "cli_keys.toml").string()}, (dir / "keyless").string());
  EXPECT_EQ(keyless.wait(30s), 1);
  EXPECT_NE(keyless.err().find("security.curve = true needs CurveZMQ keys"), std::string::npos) << keyless.err();
  Process keyed({"run", "--config", (dir / "cli_keys.toml").string(), "--server-key", (dir / "server.key").string(),
                 "--authorized-keys", (dir / "authorized").string()},
                (dir / "keyed").string());
  const std::string keyed_endpoint = wait_endpoint(dir / "cli_keys", keyed, 30s);
  ASSERT_FALSE(keyed_endpoint.empty()) << keyed.err();
  Process keyed_worker({"worker", "--connect", keyed_endpoint, "--name", "good", "--server-key", server_pub, "--key",
                        (dir / "good.key").string(), "--heartbeat-ms", "100", "--liveness", "4", "--give-up", "30"},
                       (dir / "keyed_worker").string());
  ASSERT_EQ(keyed.wait(60s), 0) << keyed.err();
  EXPECT_EQ(keyed_worker.wait(10s), 0) << keyed_worker.err();
  EXPECT_NE(keyed.err().find("CurveZMQ on"), std::string::npos) << keyed.err();
}

}  // namespace
}  // namespace drapegen::test
