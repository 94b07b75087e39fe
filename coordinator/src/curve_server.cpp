#include "curve_server.hpp"

#include <array>
#include <chrono>
#include <fmt/format.h>
#include <iterator>
#include <vector>
#include <zmq_addon.hpp>

#include "drapegen/coordinator/curve_keys.hpp"

namespace drapegen::coordinator {

bool is_loopback(const std::string& endpoint) {
  if (endpoint.rfind("ipc://", 0) == 0 || endpoint.rfind("inproc://", 0) == 0) return true;
  const auto scheme = endpoint.find("://");
  if (scheme == std::string::npos) return false;
  const std::string rest = endpoint.substr(scheme + 3);
  return rest.rfind("127.", 0) == 0 || rest.rfind("localhost:", 0) == 0 || rest.rfind("[::1]:", 0) == 0;
}

sim::Expected<std::unique_ptr<CurveServer>> CurveServer::attach(zmq::context_t& context, zmq::socket_t& server,
                                                                 const std::string& secret_key,
                                                                 const std::string& authorized_keys) {
  auto keys = read_secret_key(secret_key);
  if (!keys) return keys.error();
  auto allowed = read_authorized_keys(authorized_keys);
  if (!allowed) return allowed.error();
  std::unique_ptr<CurveServer> curve(new CurveServer(context));
  curve->authorized_ = std::move(allowed).value();
  curve->public_key_ = keys->public_z85;
  try {
    curve->zap_.set(zmq::sockopt::linger, 0);
    curve->zap_.bind("inproc://zeromq.zap.01");
    server.set(zmq::sockopt::curve_server, 1);
    server.set(zmq::sockopt::curve_secretkey, keys->secret_z85);
    server.set(zmq::sockopt::zap_domain, "drapegen");
  } catch (const zmq::error_t& e) {
    return sim::Error{fmt::format("cannot set up CurveZMQ: {}", e.what())};
  }
  return curve;
}

void CurveServer::answer() {
  std::vector<zmq::message_t> request;
  if (!zmq::recv_multipart(zap_, std::back_inserter(request), zmq::recv_flags::dontwait)) return;
  std::string status = "400", text = "unauthorised key";
  if (request.size() >= 7 && request[5].to_string() == "CURVE" && authorized_.count(request[6].to_string())) {
    status = "200";
    text = "OK";
  } else {
    ++refused_;
    const auto now = std::chrono::steady_clock::now();
    if (now - last_refuse_log_ > std::chrono::seconds(1)) {
      logger()->warn("refused a connection from {} ({}; {} refused so far)",
                     request.size() > 3 ? request[3].to_string() : "?",
                     request.size() > 5 ? request[5].to_string() : "no mechanism", refused_);
      last_refuse_log_ = now;
    }
  }
  const std::string version = "1.0";
  const std::string id = request.size() > 1 ? request[1].to_string() : "";
  std::array<zmq::const_buffer, 6> reply = {zmq::buffer(version), zmq::buffer(id),   zmq::buffer(status),
                                            zmq::buffer(text),    zmq::buffer("", 0), zmq::buffer("", 0)};
  zmq::send_multipart(zap_, reply);
}

}  // namespace drapegen::coordinator
