// drapegen keygen: a CurveZMQ key pair for the coordinator or a worker (docs/SERVICE.md, "Security").
#include <filesystem>
#include <iostream>
#include <memory>

#include "commands.hpp"
#include "drapegen/coordinator/curve_keys.hpp"
#include "failure.hpp"
#include "parse.hpp"

namespace drapegen::cli {

Runner add_keygen_command(CLI::App& app) {
  auto prefix = std::make_shared<std::string>();
  auto force = std::make_shared<bool>(false);
  app.add_option("--out", *prefix, "Write PREFIX.key (secret, mode 0600) and PREFIX.pub (public)")->required();
  app.add_flag("--force", *force, "Replace an existing key pair (every peer holding the old public key is cut off)");
  return [prefix, force]() -> int {
    const Failure fail{"keygen"};
    for (const char* suffix : {".key", ".pub"}) {
      if (!*force && std::filesystem::exists(*prefix + suffix)) {
        return fail(*prefix + suffix +
                    " exists already: the peers that hold its public key would be cut off; use "
                    "--force to replace it");
      }
      // Both checked before either is written: a pair replaced by half (a new secret key, no public key to match it)
      // would cut every peer off.
      if (sim::Status s = check_writable(*prefix + suffix); !s) return fail(s.error().message, kExitIo);
    }
    auto pair = coordinator::make_curve_keypair();
    if (!pair) return fail(pair.error().message);
    if (sim::Status s = coordinator::write_curve_keypair(*pair, *prefix); !s) return fail(s.error().message, kExitIo);
    std::cout << pair->public_z85 << "\n";
    return kExitOk;
  };
}

}  // namespace drapegen::cli
