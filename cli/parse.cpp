#include "parse.hpp"

#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <cstdlib>
#include <unistd.h>
#include <sstream>
#include <vector>

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

sim::Status check_writable(const std::string& path) {
  // A unique probe beside the target (never touches an existing file), removed again.
  std::string probe = path + ".probe-XXXXXX";
  const int fd = ::mkstemp(probe.data());
  if (fd < 0) return sim::Error{"cannot write '" + path + "': " + std::strerror(errno)};
  ::close(fd);
  std::remove(probe.c_str());
  return {};
}

}  // namespace drapegen::cli
