#include "drapegen/sampler/fabric_data.hpp"

#include <cerrno>
#include <cstring>
#include <array>
#include <charconv>
#include <cmath>
#include <fstream>
#include <map>
#include <string_view>

namespace drapegen::sampler {
namespace {

bool parse_double(std::string_view text, double& out) {
  while (!text.empty() && (text.front() == ' ' || text.front() == '\t')) text.remove_prefix(1);
  while (!text.empty() && (text.back() == ' ' || text.back() == '\t' || text.back() == '\r')) text.remove_suffix(1);
  if (text.empty()) return false;
  const auto [end, ec] = std::from_chars(text.data(), text.data() + text.size(), out);
  return ec == std::errc() && end == text.data() + text.size() && std::isfinite(out);
}

/// Whether `line` is fabrics618.csv's header: seven fields, density first, then the directions in the order the
/// reader maps them (warp, weft, diag; linear, then nonlinear). A file without it would lose its first fabric.
bool is_header(std::string_view line) {
  constexpr std::array<std::string_view, 7> kNames = {"density", "warp", "weft", "diag", "warp", "weft", "diag"};
  std::size_t field = 0;
  while (true) {
    const std::size_t comma = line.find(',');
    const std::string_view text = line.substr(0, comma);
    if (field >= kNames.size() || text.find(kNames[field]) == std::string_view::npos) return false;
    // The linear block first, then the nonlinear one (a swapped file would put beta into alpha).
    const bool nonlinear = text.find("nonlinear") != std::string_view::npos;
    if (field >= 1 && (nonlinear != (field >= 4) || text.find("linear") == std::string_view::npos)) return false;
    ++field;
    if (comma == std::string_view::npos) break;
    line.remove_prefix(comma + 1);
  }
  return field == kNames.size();
}

}  // namespace

sim::Expected<std::vector<MeasuredFabric>> read_fabric_csv(const std::string& path) {
  std::ifstream in(path);
  if (!in) return sim::Error{"cannot open fabric data '" + path + "': " + std::strerror(errno)};
  std::string line;
  if (!std::getline(in, line)) return sim::Error{"fabric data '" + path + "' is empty or unreadable"};
  if (!is_header(line)) {
    return sim::Error{"fabric data '" + path + "' line 1: expected the header (density, linear warp, linear weft, "
                      "linear diag, nonlinear warp, nonlinear weft, nonlinear diag), which fixes the columns' order"};
  }
  std::vector<MeasuredFabric> fabrics;
  int line_number = 1;
  while (std::getline(in, line)) {
    ++line_number;
    if (line.find_first_not_of(" \t\r") == std::string::npos) continue;
    double v[7];
    std::size_t start = 0;
    int count = 0;
    bool ok = true;
    while (ok) {
      const std::size_t comma = line.find(',', start);
      const std::string_view field(line.data() + start, (comma == std::string::npos ? line.size() : comma) - start);
      if (count == 7 || !parse_double(field, v[count])) ok = false;
      ++count;
      if (comma == std::string::npos) break;
      start = comma + 1;
    }
    if (!ok || count != 7) {
      return sim::Error{"fabric data '" + path + "' line " + std::to_string(line_number) +
                        ": expected 7 finite numbers (density, 3 linear and 3 nonlinear moduli)"};
    }
    if (!(v[0] > 0.0) || v[1] == 0.0 || v[2] == 0.0 || v[3] == 0.0 || v[4] == 0.0 || v[5] == 0.0 || v[6] == 0.0) {
      return sim::Error{"fabric data '" + path + "' line " + std::to_string(line_number) +
                        ": density must be positive and moduli non-zero"};
    }
    if (!(v[1] > 0.0 && v[2] > 0.0 && v[3] > 0.0)) {
      return sim::Error{"fabric data '" + path + "' line " + std::to_string(line_number) +
                        ": the linear moduli (bending stiffness) must be positive"};
    }
    MeasuredFabric f;
    f.density_g_per_m2 = v[0] * 1e3;
    // CSV: warp, weft, diag; the paper (and DirectionalValues): warp, bias (= diag), weft.
    f.moduli.alpha = {v[1], v[3], v[2]};
    f.moduli.beta = {v[4], v[6], v[5]};
    // The features sign(k) ln|k| are one-to-one only for |k| > 1 (at 300 g/m^2, paper units): a smaller modulus is
    // in other units (SI rather than SI*1e9 and SI*1e12) and would turn into a feature of the other sign.
    const ParameterVector n = normalise_density(f.moduli, f.density_g_per_m2);
    for (const double k : {n.alpha.warp, n.alpha.bias, n.alpha.weft, n.beta.warp, n.beta.bias, n.beta.weft}) {
      if (std::abs(k) <= 1.0) {
        return sim::Error{"fabric data '" + path + "' line " + std::to_string(line_number) + ": a modulus of " +
                          std::to_string(k) + " at 300 g/m^2 (|k| <= 1): the columns are in SI*1e9 (linear) and " +
                          "SI*1e12 (nonlinear), density in kg/m^2"};
      }
    }
    fabrics.push_back(f);
  }
  if (in.bad()) return sim::Error{"error reading fabric data '" + path + "'"};
  if (fabrics.empty()) return sim::Error{"fabric data '" + path + "' has no rows"};
  return fabrics;
}

std::vector<Features> distinct_features(const std::vector<MeasuredFabric>& fabrics) {
  std::vector<Features> out;
  std::map<std::array<double, 7>, bool> seen;
  for (const MeasuredFabric& f : fabrics) {
    const std::array<double, 7> key{f.density_g_per_m2, f.moduli.alpha.warp, f.moduli.alpha.bias,
                                    f.moduli.alpha.weft, f.moduli.beta.warp,  f.moduli.beta.bias,
                                    f.moduli.beta.weft};
    if (!seen.emplace(key, true).second) continue;
    out.push_back(to_features(normalise_density(f.moduli, f.density_g_per_m2)));
  }
  return out;
}

}  // namespace drapegen::sampler
