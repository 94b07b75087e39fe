#pragma once
// CurveZMQ keys for the service (docs/SERVICE.md, "Security"): Z85 text files, one key per line.

#include <set>
#include <string>

#include "drapegen/sim/expected.hpp"

namespace drapegen::coordinator {

struct CurveKeyPair {
  std::string public_z85;  // 40 characters
  std::string secret_z85;
};

/// A fresh key pair (libzmq's zmq_curve_keypair; needs a libzmq built with CURVE).
[[nodiscard]] sim::Expected<CurveKeyPair> make_curve_keypair();
/// Writes PREFIX.key (the secret key, mode 0600) and PREFIX.pub (the public key).
[[nodiscard]] sim::Status write_curve_keypair(const CurveKeyPair& pair, const std::string& prefix);
/// Reads a secret key file and derives the public key.
[[nodiscard]] sim::Expected<CurveKeyPair> read_secret_key(const std::string& path);
/// A public key given inline (40 Z85 characters) or as a file holding one.
[[nodiscard]] sim::Expected<std::string> read_public_key(const std::string& path_or_key);
/// Public keys, one per line (a line starting with '#' is a comment), as raw 32-byte strings (what ZAP requests carry).
[[nodiscard]] sim::Expected<std::set<std::string>> read_authorized_keys(const std::string& path);

}  // namespace drapegen::coordinator
