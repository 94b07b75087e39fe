#include "parse.hpp"

#include "commands.hpp"
#include "drapegen/coordinator/run_config.hpp"

#include <algorithm>
#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <iostream>
#include <sstream>
#include <vector>

#include "drapegen/storage/atomic_file.hpp"

namespace drapegen::cli {

sim::Expected<sim::DirectionalValues> parse_directional(const std::string& text, const std::string& what) {
  std::vector<double> values;
  std::stringstream stream(text);
  std::string item;
  while (std::getline(stream, item, ',')) {
    std::size_t used = 0;
    double v = 0.0;
    try {
      v = std::stod(item, &used);
    } catch (const std::exception&) {
      used = 0;
    }
    if (used == 0 || used != item.size() || !std::isfinite(v)) {
      return sim::Error{what + ": '" + item + "' is not a finite number"};
    }
    values.push_back(v);
  }
  if (values.size() == 1) return sim::DirectionalValues{values[0], values[0], values[0]};
  if (values.size() == 3 && !text.empty() && text.back() != ',') {
    return sim::DirectionalValues{values[0], values[1], values[2]};
  }
  return sim::Error{what + ": expected W,B,F (warp, bias, weft) or one value, got '" + text + "'"};
}

sim::Expected<sim::PhysicalEffects> parse_effects(const std::vector<std::string>& items) {
  sim::PhysicalEffects effects;
  auto number = [](const std::string& text, double& out) {
    std::size_t used = 0;
    try {
      out = std::stod(text, &used);
    } catch (const std::exception&) {
      return false;
    }
    return used == text.size() && std::isfinite(out);
  };
  for (const std::string& item : items) {
    const auto eq = item.find('=');
    const std::string name = item.substr(0, eq), value = eq == std::string::npos ? "" : item.substr(eq + 1);
    const std::string usage = "--effect " + item + ": ";
    if (eq == std::string::npos || value.empty()) {
      return sim::Error{usage + "expected NAME=VALUE with NAME curl, yield, shear or friction"};
    }
    double v = 0.0;
    if (name == "curl") {
      if (effects.edge_curl) return sim::Error{usage + "curl given twice"};
      const auto comma = value.find(',');
      double width_mm = 10.0;
      if (!number(value.substr(0, comma), v) ||
          (comma != std::string::npos && !(number(value.substr(comma + 1), width_mm) && width_mm > 0.0))) {
        return sim::Error{usage + "expected curl=K or curl=K,W (K in 1/m, W > 0 in mm)"};
      }
      effects.edge_curl = sim::EdgeCurl{v, width_mm * 1e-3};
    } else if (name == "yield") {
      if (effects.bending_yield_curvature) return sim::Error{usage + "yield given twice"};
      if (!number(value, v) || !(v > 0.0)) return sim::Error{usage + "expected yield=K with K > 0 in 1/m"};
      effects.bending_yield_curvature = v;
    } else if (name == "shear") {
      if (effects.shear_stiffness) return sim::Error{usage + "shear given twice"};
      if (!number(value, v) || !(v >= 0.0)) return sim::Error{usage + "expected shear=G with G >= 0 in kg/s^2"};
      effects.shear_stiffness = v;
    } else if (name == "friction") {
      if (effects.friction) return sim::Error{usage + "friction given twice"};
      if (!number(value, v) || !(v >= 0.0)) return sim::Error{usage + "expected friction=MU with MU >= 0"};
      effects.friction = sim::FrictionParameters{v};
    } else {
      return sim::Error{usage + "unknown effect '" + name + "' (curl, yield, shear or friction)"};
    }
  }
  return effects;
}

std::ostream& summary_stream(const std::vector<std::string>& outputs) {
  struct stat out {};
  if (::fstat(STDOUT_FILENO, &out) != 0) return std::cout;
  for (const std::string& path : outputs) {
    struct stat st {};
    if (!path.empty() && ::stat(path.c_str(), &st) == 0 && st.st_dev == out.st_dev && st.st_ino == out.st_ino) {
      return std::cerr;
    }
  }
  return std::cout;
}

std::string endpoint_problem(const std::string& endpoint) { return coordinator::endpoint_problem(endpoint); }

bool is_decimal_integer(const std::string& text) {
  const std::size_t sign = !text.empty() && (text[0] == '+' || text[0] == '-') ? 1 : 0;
  return text.size() > sign && text.find_first_not_of("0123456789", sign) == std::string::npos;
}

std::string decimal_integer(std::string text) {
  if (!is_decimal_integer(text)) return text;
  const std::size_t sign = text[0] == '+' || text[0] == '-' ? 1 : 0;
  const std::size_t first = std::min(text.find_first_not_of('0', sign), text.size() - 1);
  return text.substr(0, sign) + text.substr(first);
}

bool same_file(const std::string& a, const std::string& b) {
  std::error_code ec;
  if (std::filesystem::equivalent(a, b, ec) && !ec) return true;
  const auto ca = std::filesystem::weakly_canonical(a, ec);
  if (ec) return a == b;
  const auto cb = std::filesystem::weakly_canonical(b, ec);
  return ec ? a == b : ca == cb;
}

sim::Status check_writable(const std::string& path) {
  std::error_code ec;
  if (std::filesystem::is_directory(path, ec)) return sim::Error{"cannot write '" + path + "': it is a directory"};
  // Written in place (a device, a pipe, /dev/stdout; storage::written_in_place): open it, as the write will (a probe
  // beside it, in /dev, needs rights the write does not). No reader on a FIFO yet (ENXIO) is not an error.
  if (storage::written_in_place(path)) {
    const int fd = ::open(path.c_str(), O_WRONLY | O_APPEND | O_NOCTTY | O_NONBLOCK | O_CLOEXEC);
    if (fd < 0 && errno != ENXIO) return sim::Error{"cannot write '" + path + "': " + std::strerror(errno)};
    if (fd >= 0) ::close(fd);
    return {};
  }
  // A unique probe beside the target (never touches an existing file), removed again.
  std::string probe = path + ".probe-XXXXXX";
  const int fd = ::mkstemp(probe.data());
  if (fd < 0) return sim::Error{"cannot write '" + path + "': " + std::strerror(errno)};
  ::close(fd);
  std::remove(probe.c_str());
  return {};
}

sim::Status prepare_output_directory(const std::string& directory, const std::string& file) {
  std::error_code ec;
  std::filesystem::create_directories(directory, ec);
  if (ec) return sim::Error{directory + ": cannot create directory: " + ec.message()};
  return check_writable((std::filesystem::path(directory) / file).string());
}

}  // namespace drapegen::cli
