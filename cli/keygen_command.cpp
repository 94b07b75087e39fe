// drapegen keygen: a CurveZMQ key pair for the coordinator or a worker (docs/SERVICE.md, "Security").
#include <iostream>
#include <memory>

#include "commands.hpp"
#include "failure.hpp"
#include "drapegen/coordinator/curve_keys.hpp"

namespace drapegen::cli {

Runner add_keygen_command(CLI::App& app) {
  auto prefix = std::make_shared<std::string>();
  app.add_option("--out", *prefix, "Write PREFIX.key (secret, mode 0600) and PREFIX.pub (public)")->required();
  return [prefix]() -> int {
    auto pair = coordinator::make_curve_keypair();
    const Failure fail{"keygen"};
    if (!pair) return fail(pair.error().message);
    if (sim::Status s = coordinator::write_curve_keypair(*pair, *prefix); !s) return fail(s.error().message, kExitIo);
    std::cout << pair->public_z85 << "\n";
    return kExitOk;
  };
}

}  // namespace drapegen::cli
