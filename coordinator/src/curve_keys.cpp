#include "drapegen/coordinator/curve_keys.hpp"

#include <filesystem>
#include <fmt/format.h>
#include <fstream>
#include <sys/stat.h>
#include <vector>
#include <zmq.h>

#include "drapegen/storage/atomic_file.hpp"

namespace drapegen::coordinator {
namespace {

std::vector<std::string> key_lines(const std::string& path, std::string& error) {
  std::ifstream in(path);
  if (!in) {
    error = "cannot read key file " + path;
    return {};
  }
  std::vector<std::string> out;
  std::string line;
  while (std::getline(in, line)) {
    // Z85 uses '#', so only whole lines are comments.
    const auto b = line.find_first_not_of(" \t\r");
    if (b == std::string::npos || line[b] == '#') continue;
    line = line.substr(b, line.find_last_not_of(" \t\r") - b + 1);
    out.push_back(line);
  }
  return out;
}

bool valid_z85_key(const std::string& z85, std::string* raw = nullptr) {
  if (z85.size() != 40) return false;
  std::uint8_t bytes[32];
  if (!zmq_z85_decode(bytes, z85.c_str())) return false;
  if (raw) raw->assign(reinterpret_cast<const char*>(bytes), 32);
  return true;
}

}  // namespace

sim::Expected<CurveKeyPair> make_curve_keypair() {
  if (!zmq_has("curve")) return sim::Error{"this libzmq has no CURVE support"};
  char pub[41] = {}, sec[41] = {};
  if (zmq_curve_keypair(pub, sec) != 0) return sim::Error{"zmq_curve_keypair failed"};
  return CurveKeyPair{pub, sec};
}

sim::Status write_curve_keypair(const CurveKeyPair& pair, const std::string& prefix) {
  const std::string secret = prefix + ".key", pub = prefix + ".pub";
  if (sim::Status s = storage::write_file_atomic(
          secret, "# drapegen CurveZMQ secret key (keep private)\n" + pair.secret_z85 + "\n", 0600);
      !s) {
    return s;
  }
  return storage::write_file_atomic(pub, pair.public_z85 + "\n");
}

sim::Expected<CurveKeyPair> read_secret_key(const std::string& path) {
  std::string error;
  const auto lines = key_lines(path, error);
  if (!error.empty()) return sim::Error{error};
  if (lines.size() != 1 || !valid_z85_key(lines[0])) {
    return sim::Error{fmt::format("{}: expected one 40-character Z85 secret key (drapegen keygen writes one)", path)};
  }
  char pub[41] = {};
  if (zmq_curve_public(pub, lines[0].c_str()) != 0) return sim::Error{path + ": cannot derive the public key"};
  return CurveKeyPair{pub, lines[0]};
}

sim::Expected<std::string> read_public_key(const std::string& path_or_key) {
  if (valid_z85_key(path_or_key) && !std::filesystem::exists(path_or_key)) return path_or_key;
  std::string error;
  const auto lines = key_lines(path_or_key, error);
  if (!error.empty()) return sim::Error{error};
  if (lines.size() != 1 || !valid_z85_key(lines[0])) {
    return sim::Error{fmt::format("{}: expected one 40-character Z85 public key", path_or_key)};
  }
  return lines[0];
}

sim::Expected<std::set<std::string>> read_authorized_keys(const std::string& path) {
  std::string error;
  const auto lines = key_lines(path, error);
  if (!error.empty()) return sim::Error{error};
  std::set<std::string> keys;
  for (std::size_t i = 0; i < lines.size(); ++i) {
    std::string raw;
    if (!valid_z85_key(lines[i], &raw)) {
      return sim::Error{fmt::format("{}: key {} is not a 40-character Z85 public key", path, i + 1)};
    }
    keys.insert(raw);
  }
  if (keys.empty()) return sim::Error{path + ": no worker keys"};
  return keys;
}

}  // namespace drapegen::coordinator
