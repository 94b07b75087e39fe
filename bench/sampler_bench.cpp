// Throughput of the parameter sampler (docs/BENCHMARKS.md): 6,000 parameter vectors from the committed VAE with the
// paper's widened sampling and rejection, plus their 48,000 initial-state recipes (and, separately, their text form).
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <vector>

#include <CLI/CLI.hpp>
#include <fmt/format.h>

#include "drapegen/sampler/parameter_sampler.hpp"
#include "drapegen/sampler/recipe_generator.hpp"
#include "drapegen/sim/median.hpp"

int main(int argc, char** argv) {
  using namespace drapegen::sampler;
  CLI::App app{"drapegen sampler throughput"};
  int n = 6000, states = 8, repeats = 7;
  std::uint64_t seed = 7;
  std::string model_path = default_model_path();
  app.add_option("--n", n, "parameter vectors")->capture_default_str();
  app.add_option("--states", states, "initial states per vector")->capture_default_str();
  app.add_option("--repeats", repeats, "timed repetitions")->capture_default_str();
  app.add_option("--seed", seed, "seed")->capture_default_str();
  app.add_option("--model", model_path, "model file")->capture_default_str();
  CLI11_PARSE(app, argc, argv);
  auto model = load_vae_model(model_path);
  if (!model) {
    std::fprintf(stderr, "sampler_bench: error: %s\n", model.error().message.c_str());
    return 1;
  }
  using clock = std::chrono::steady_clock;
  auto ms = [](clock::duration d) { return std::chrono::duration<double, std::milli>(d).count(); };
  std::vector<double> total, sampling, recipes, text;
  std::size_t checksum = 0;
  for (int r = 0; r < repeats; ++r) {
    const auto t0 = clock::now();
    SamplerOptions options;
    options.count = n;
    options.seed = seed;
    auto sampled = sample_parameters(*model, options);
    if (!sampled) {
      std::fprintf(stderr, "sampler_bench: error: %s\n", sampled.error().message.c_str());
      return 1;
    }
    const auto t1 = clock::now();
    RecipeOptions ro;
    ro.seed = seed;
    ro.states_per_sample = states;
    std::vector<InitialStateRecipe> all;
    all.reserve(static_cast<std::size_t>(n) * states);
    for (int i = 0; i < n; ++i) {
      for (const auto& rec : make_recipes_in_order(ro, i)) all.push_back(rec);
    }
    const auto t2 = clock::now();
    std::size_t bytes = 0;
    for (const auto& rec : all) bytes += to_text(rec).size();
    const auto t3 = clock::now();
    checksum += all.size() + sampled->candidates + bytes;
    sampling.push_back(ms(t1 - t0));
    recipes.push_back(ms(t2 - t1));
    text.push_back(ms(t3 - t2));
    total.push_back(ms(t2 - t0));
  }
  using drapegen::sim::median;
  fmt::print("{} vectors + {} recipes, {} repeats (median / min): total {:.1f} / {:.1f} ms = sampling {:.1f} ms + "
             "recipes {:.1f} ms; recipe text form {:.1f} ms extra (checksum {})\n",
             n, static_cast<long>(n) * states, repeats, median(total), *std::min_element(total.begin(), total.end()),
             median(sampling), median(recipes), median(text), checksum);
  return 0;
}
