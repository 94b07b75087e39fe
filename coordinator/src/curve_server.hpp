#pragma once
// The server side of CurveZMQ, shared by the generation coordinator and the diagnosis's fleet: the server key on a
// ROUTER socket and a ZAP handler (RFC 27) that admits only the authorised client keys; and which endpoints need it.

#include <chrono>
#include <cstdint>
#include <memory>
#include <set>
#include <string>
#include <zmq.hpp>

#include "drapegen/coordinator/logging.hpp"
#include "drapegen/sim/expected.hpp"

namespace drapegen::coordinator {

/// Endpoints only this machine can reach (ipc, inproc, 127.x, localhost, [::1]): the ones that may go without
/// authentication.
[[nodiscard]] bool is_loopback(const std::string& endpoint);

class CurveServer {
 public:
  /// Makes `server` (not bound yet) a CURVE server with the secret key file `secret_key` that admits the public keys
  /// listed in `authorized_keys`, and binds the ZAP handler in `context` (one per context).
  [[nodiscard]] static sim::Expected<std::unique_ptr<CurveServer>> attach(zmq::context_t& context,
                                                                          zmq::socket_t& server,
                                                                          const std::string& secret_key,
                                                                          const std::string& authorized_keys);
  /// The ZAP handler's socket: poll it for ZMQ_POLLIN, then answer().
  [[nodiscard]] zmq::socket_t& socket() { return zap_; }
  /// Answers one waiting handshake (none waiting: nothing); logs refused ones, a line a second at most.
  void answer();
  [[nodiscard]] std::size_t authorized() const { return authorized_.size(); }
  [[nodiscard]] const std::string& public_key() const { return public_key_; }
  [[nodiscard]] std::int64_t refused() const { return refused_; }

 private:
  explicit CurveServer(zmq::context_t& context) : zap_(context, zmq::socket_type::rep) {}
  zmq::socket_t zap_;
  std::set<std::string> authorized_;  // raw 32-byte client public keys
  std::string public_key_;            // Z85
  std::int64_t refused_ = 0;
  std::chrono::steady_clock::time_point last_refuse_log_{};
};

}  // namespace drapegen::coordinator
