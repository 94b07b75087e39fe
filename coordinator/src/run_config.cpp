#include "drapegen/coordinator/run_config.hpp"

#include <fmt/format.h>
#include <toml++/toml.h>

#include <cmath>
#include <set>
#include <sstream>

#include "drapegen/sampler/recipe_generator.hpp"

namespace drapegen::coordinator {
namespace {

class Reader {
 public:
  Reader(const toml::table& root, std::string source) : root_(root), source_(std::move(source)) {}

  const std::string& error() const { return error_; }
  bool ok() const { return error_.empty(); }

  void fail(const std::string& key, const std::string& message) {
    if (error_.empty()) error_ = fmt::format("{}: {}: {}", source_, key, message);
  }

  const toml::table* table(const std::string& name) {
    const toml::node* node = root_.get(name);
    if (!node) return nullptr;
    if (!node->is_table()) {
      fail(name, "must be a table ([" + name + "])");
      return nullptr;
    }
    return node->as_table();
  }

  /// Reads an integer key into `out` within [low, high].
  template <class T>
  void integer(const toml::table* t, const std::string& section, const std::string& key, T& out, std::int64_t low,
               std::int64_t high) {
    const toml::node* node = t ? t->get(key) : nullptr;
    if (!node) return;
    const std::string name = section.empty() ? key : section + "." + key;
    if (!node->is_integer()) return fail(name, "must be an integer");
    const std::int64_t v = node->as_integer()->get();
    if (v < low || v > high) return fail(name, fmt::format("must be between {} and {}", low, high));
    out = static_cast<T>(v);
  }

  void real(const toml::table* t, const std::string& section, const std::string& key, double& out, double low,
            double high) {
    const toml::node* node = t ? t->get(key) : nullptr;
    if (!node) return;
    const std::string name = section.empty() ? key : section + "." + key;
    double v;
    if (node->is_floating_point()) {
      v = node->as_floating_point()->get();
    } else if (node->is_integer()) {
      v = static_cast<double>(node->as_integer()->get());
    } else {
      return fail(name, "must be a number");
    }
    if (!std::isfinite(v) || v < low || v > high)
      return fail(name, fmt::format("must be between {} and {}", low, high));
    out = v;
  }

  void text(const toml::table* t, const std::string& section, const std::string& key, std::string& out,
            const std::set<std::string>& allowed = {}) {
    const toml::node* node = t ? t->get(key) : nullptr;
    if (!node) return;
    const std::string name = section.empty() ? key : section + "." + key;
    if (!node->is_string()) return fail(name, "must be a string");
    const std::string v = node->as_string()->get();
    if (!allowed.empty() && !allowed.count(v)) {
      std::string list;
      for (const auto& a : allowed) list += (list.empty() ? "" : ", ") + a;
      return fail(name, fmt::format("'{}' is not one of {}", v, list));
    }
    out = v;
  }

  void only_keys(const toml::table* t, const std::string& section, const std::set<std::string>& keys) {
    if (!t) return;
    for (const auto& [k, v] : *t) {
      const std::string key(k.str());
      if (!keys.count(key)) {
        fail(section.empty() ? key : section + "." + key,
             section.empty() && v.is_table() ? "unknown section" : "unknown key");
      }
    }
  }

 private:
  const toml::table& root_;
  std::string source_;
  std::string error_;
};

/// The TOML text as a table, or its first syntax error with line and column.
sim::Expected<toml::table> parse_toml(const std::string& toml_text, const std::string& source_name) {
  try {
    return toml::parse(toml_text, source_name);
  } catch (const toml::parse_error& e) {
    const auto& where = e.source().begin;
    return sim::Error{fmt::format("{}:{}:{}: {}", source_name, where.line, where.column, e.description())};
  }
}

}  // namespace

sim::Expected<std::string> with_output(const std::string& toml_text, const std::string& source_name,
                                       const std::string& output) {
  auto parsed = parse_toml(toml_text, source_name);
  if (!parsed) return parsed.error();
  toml::table& root = *parsed;
  root.insert_or_assign("output", output);
  std::ostringstream text;
  text << root << '\n';
  return text.str();
}

std::string endpoint_problem(const std::string& endpoint) {
  const std::string example = "e.g. tcp://127.0.0.1:5555, tcp://*:* or ipc:///tmp/drapegen.sock";
  if (endpoint.rfind("ipc://", 0) == 0) {
    return endpoint.size() > 6 ? "" : fmt::format("'{}' names no path ({})", endpoint, example);
  }
  if (endpoint.rfind("tcp://", 0) != 0) {
    return fmt::format("'{}' is not a tcp:// or ipc:// endpoint ({})", endpoint, example);
  }
  const std::string rest = endpoint.substr(6);
  const std::size_t colon = rest.rfind(':');
  if (colon == std::string::npos || colon == 0) {
    return fmt::format("'{}' needs a host and a port, tcp://HOST:PORT ({})", endpoint, example);
  }
  const std::string port = rest.substr(colon + 1);
  if (port == "*") return "";
  const bool digits = !port.empty() && port.size() <= 5 && port.find_first_not_of("0123456789") == std::string::npos;
  if (const int number = digits ? std::stoi(port) : 0; number < 1 || number > 65535) {
    return fmt::format("'{}': the port must be 1 .. 65535 or * (any free port)", endpoint);
  }
  return "";
}

sim::Status check_new_run(const RunConfig& c, const std::string& source_name) {
  const auto fail = [&](const char* key, const std::string& message) {
    return sim::Error{fmt::format("{}: {}: {}", source_name, key, message)};
  };
  // The plan is built in memory before the manifest is written: 10^7 x 64 jobs would have needed hundreds of GB and
  // ended in "out of memory" without naming the keys.
  constexpr std::int64_t kMaxJobs = 2'000'000;
  if (const std::int64_t jobs = static_cast<std::int64_t>(c.samples) * c.states_per_sample; jobs > kMaxJobs) {
    return fail("samples", fmt::format("samples x states_per_sample is {} jobs; at most {} in one run (the plan is "
                                       "built in memory: split the run, e.g. by seed)",
                                       jobs, kMaxJobs));
  }
  if (c.coarse_start_resolution == 1 || c.coarse_start_resolution == 2) {
    return fail("solver.coarse_start_resolution", "must be 0 (off) or at least 3");  // as simulate --coarse-start
  }
  if (const std::string problem = endpoint_problem(c.bind); !problem.empty()) return fail("network.bind", problem);
  return {};
}

sim::Expected<RunConfig> parse_run_config(const std::string& toml_text, const std::string& source_name) {
  auto parsed = parse_toml(toml_text, source_name);
  if (!parsed) return parsed.error();
  toml::table& root = *parsed;
  RunConfig c;
  Reader r(root, source_name);
  r.only_keys(
      &root, "",
      {"seed", "samples", "states_per_sample", "orientations", "resolution", "noise", "renderer", "density",
       "bending_model", "output", "model", "recipes", "solver", "network", "security", "retry", "progress", "testing"});
  if (const toml::node* seed = root.get("seed")) {
    if (!seed->is_integer() || seed->as_integer()->get() < 0) {
      r.fail("seed", "must be a non-negative integer");
    } else {
      c.seed = static_cast<std::uint64_t>(seed->as_integer()->get());
    }
  }
  r.integer(&root, "", "samples", c.samples, 1, 10'000'000);
  r.integer(&root, "", "states_per_sample", c.states_per_sample, 1, 64);
  r.integer(&root, "", "orientations", c.orientations, 1, 360);
  r.integer(&root, "", "resolution", c.resolution, 5, 400);
  r.text(&root, "", "noise", c.noise, {"kinect", "none"});
  r.text(&root, "", "renderer", c.renderer, {"osmesa", "software"});
  r.real(&root, "", "density", c.density, 1.0, 1e5);
  r.text(&root, "", "bending_model", c.bending_model, {"dihedral", "triangle"});
  r.text(&root, "", "output", c.output);
  r.text(&root, "", "model", c.model);
  if (r.ok() && c.output.empty()) r.fail("output", "must not be empty");

  const toml::table* recipes = r.table("recipes");
  r.only_keys(recipes, "recipes", {"weight_sine", "weight_fold", "weight_drape", "max_drift_mm"});
  r.real(recipes, "recipes", "weight_sine", c.weight_sine, 0.0, 1e6);
  r.real(recipes, "recipes", "weight_fold", c.weight_fold, 0.0, 1e6);
  r.real(recipes, "recipes", "weight_drape", c.weight_drape, 0.0, 1e6);
  r.real(recipes, "recipes", "max_drift_mm", c.max_drift_mm, 0.0, sampler::kMaxDriftMm);
  if (r.ok() && !(c.weight_sine + c.weight_fold > 0.0)) {
    r.fail("recipes", "weight_sine + weight_fold must be positive (a drape recipe needs a fallback)");
  }

  const toml::table* solver = r.table("solver");
  r.only_keys(solver, "solver", {"max_iterations", "tolerance", "coarse_start_resolution", "max_self_intersections"});
  r.integer(solver, "solver", "max_iterations", c.max_iterations, 1, 100000);
  r.real(solver, "solver", "tolerance", c.tolerance, 1e-12, 1.0);
  r.integer(solver, "solver", "coarse_start_resolution", c.coarse_start_resolution, 0, 400);
  r.integer(solver, "solver", "max_self_intersections", c.max_self_intersections, 0, 1'000'000);

  const toml::table* network = r.table("network");
  r.only_keys(network, "network", {"bind", "heartbeat_ms", "liveness", "lease_s"});
  r.text(network, "network", "bind", c.bind);
  r.integer(network, "network", "heartbeat_ms", c.heartbeat_ms, 10, 600000);
  r.integer(network, "network", "liveness", c.liveness, 2, 1000);
  r.real(network, "network", "lease_s", c.lease_s, 0.1, 7 * 86400.0);
  if (r.ok() && c.bind.rfind("tcp://", 0) != 0 && c.bind.rfind("ipc://", 0) != 0) {
    r.fail("network.bind", "must be a tcp:// or ipc:// endpoint, e.g. tcp://127.0.0.1:5555");
  }

  const toml::table* security = r.table("security");
  r.only_keys(security, "security", {"curve", "server_secret_key", "authorized_keys"});
  if (security) {
    if (const toml::node* curve = security->get("curve")) {
      if (!curve->is_boolean()) {
        r.fail("security.curve", "must be true or false");
      } else {
        c.curve = curve->as_boolean()->get();
      }
    }
  }
  r.text(security, "security", "server_secret_key", c.server_secret_key);
  r.text(security, "security", "authorized_keys", c.authorized_keys);
  if (r.ok() && c.server_secret_key.empty() != c.authorized_keys.empty()) {
    r.fail("security", "server_secret_key and authorized_keys go together");
  }

  const toml::table* retry = r.table("retry");
  r.only_keys(retry, "retry", {"max_attempts"});
  r.integer(retry, "retry", "max_attempts", c.max_attempts, 1, 1000);

  const toml::table* progress = r.table("progress");
  r.only_keys(progress, "progress", {"interval_s"});
  r.real(progress, "progress", "interval_s", c.progress_interval_s, 0.1, 86400.0);

  const toml::table* testing = r.table("testing");
  r.only_keys(testing, "testing", {"mode", "poison_samples", "fail_worker_start"});
  r.text(testing, "testing", "mode", c.mode, {"drape", "noop"});
  r.integer(testing, "testing", "fail_worker_start", c.fail_worker_start, 0, 4096);
  if (testing) {
    if (const toml::node* poison = testing->get("poison_samples")) {
      if (!poison->is_array()) {
        r.fail("testing.poison_samples", "must be an array of sample indices");
      } else {
        for (const auto& item : *poison->as_array()) {
          if (!item.is_integer() || item.as_integer()->get() < 0) {
            r.fail("testing.poison_samples", "must hold non-negative integers");
            break;
          }
          c.poison_samples.push_back(item.as_integer()->get());
        }
      }
    }
  }
  if (!r.ok()) return sim::Error{r.error()};
  return c;
}

const std::string& default_config_toml() {
  static const std::string text =
      R"toml(# drapegen local's embedded default: a small run with coarse meshes (docs/SERVICE.md lists every key).
seed = 1
samples = 30            # parameter vectors from the VAE sampler
states_per_sample = 4   # initial states per vector (paper: 8)
orientations = 2        # data points of 4 depth views per drape (paper: 12)
resolution = 25         # vertices per side of the 300 mm specimen (paper: 100)
noise = "kinect"
bending_model = "dihedral"   # or "triangle": mesh-independent, about 2x slower (docs/PHYSICS.md)
output = "out/local-run"

[solver]
max_iterations = 600
tolerance = 1e-3
max_self_intersections = 1000000   # coarse meshes: record self-intersections, do not reject them

[network]
bind = "tcp://127.0.0.1:*"
heartbeat_ms = 500
liveness = 6

[retry]
max_attempts = 2
)toml";
  return text;
}

}  // namespace drapegen::coordinator
