// drapegen stats: what a run's manifest holds (docs/SERVICE.md, "Statistics").
#include <iostream>
#include <memory>

#include "commands.hpp"
#include "failure.hpp"
#include "drapegen/coordinator/stats.hpp"
#include "drapegen/storage/json_text.hpp"

namespace drapegen::cli {
namespace {

struct StatsOptions {
  std::string manifest;
  bool json = false;
  std::string plots;
  std::string fabrics;
};

const Failure fail{"stats"};

}  // namespace

Runner add_stats_command(CLI::App& app) {
  auto o = std::make_shared<StatsOptions>();
  app.add_option("manifest", o->manifest, "The run's manifest (OUTPUT/manifest.sqlite)")->required();
  app.add_flag("--json", o->json, "Print the statistics as JSON");
  app.add_option("--plots", o->plots, "Also write SVG histograms into this directory");
  app.add_option("--fabrics", o->fabrics, "The measured fabrics (fabrics618.csv) to compare the parameters with");
  return [o]() -> int {
    coordinator::StatsOptions options;
    options.fabrics_csv = o->fabrics;
    options.plots_directory = o->plots;
    auto stats = coordinator::compute_stats(o->manifest, options);
    if (!stats) return fail(stats.error());  // 3 where a plot could not be written, 1 otherwise
    if (o->json) {
      std::cout << storage::json_text(*stats) << "\n";
    } else {
      std::cout << coordinator::format_stats(*stats);
      if (stats->contains("plots"))
        std::cout << "  plots: " << (*stats)["plots"].size() << " SVG files in " << o->plots << "\n";
    }
    return kExitOk;
  };
}

}  // namespace drapegen::cli
