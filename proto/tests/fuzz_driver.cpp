// A standalone driver for LLVMFuzzerTestOneInput (GCC has no libFuzzer): feeds random byte strings and mutations
// (bit flips, byte changes, truncations, insertions, splices) of valid encoded messages of every kind.
// Usage: drapegen_proto_fuzz [--runs N] [--seed S]
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <random>
#include <string>
#include <vector>

#include "drapegen/proto/codec.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size);

namespace {
namespace v1 = drapegen::proto::v1;

std::vector<std::string> corpus() {
  std::vector<std::string> out;
  v1::Envelope e;
  e.mutable_ready()->set_worker_name("host:1");
  out.push_back(drapegen::proto::encode(e));
  e.Clear();
  auto* job = e.mutable_job();
  job->set_job_id(12);
  job->set_attempt(2);
  job->set_lease_ms(60000);
  job->set_source_mesh(std::string(64, 'p'));
  auto* s = job->mutable_spec();
  s->set_mode(v1::JOB_MODE_DRAPE);
  s->set_resolution(20);
  s->set_orientations(2);
  s->set_noise("kinect");
  s->set_render_seed(~0ULL);
  s->set_max_iterations(400);
  s->set_tolerance(1e-3);
  s->mutable_parameters()->set_alpha_warp(13923);
  s->mutable_parameters()->set_alpha_bias(11455);
  s->mutable_parameters()->set_alpha_weft(8821);
  s->mutable_parameters()->set_beta_warp(-35390);
  s->mutable_parameters()->set_density_g_per_m2(300);
  s->mutable_recipe()->set_kind(v1::Recipe::KIND_DRAPE);
  s->mutable_recipe()->set_source_sample(3);
  out.push_back(drapegen::proto::encode(e));
  e.Clear();
  e.mutable_heartbeat()->set_job_id(5);
  out.push_back(drapegen::proto::encode(e));
  e.Clear();
  auto* r = e.mutable_result();
  r->set_job_id(9);
  r->set_attempt(1);
  r->mutable_metrics()->set_outcome("converged");
  r->mutable_metrics()->set_drape_coefficient(0.6);
  r->set_mesh_ply(std::string(100, 'm'));
  r->add_exr(std::string(80, 'x'));
  r->add_exr(std::string(40, 'y'));
  out.push_back(drapegen::proto::encode(e));
  e.Clear();
  e.mutable_failure()->set_job_id(9);
  e.mutable_failure()->set_attempt(3);
  e.mutable_failure()->set_reason(v1::FAILURE_REASON_NOT_CONVERGED);
  e.mutable_failure()->set_message("iteration limit");
  out.push_back(drapegen::proto::encode(e));
  e.Clear();
  e.mutable_shutdown()->set_reason("done");
  out.push_back(drapegen::proto::encode(e));
  e.Clear();
  e.mutable_disconnect()->set_reason("unknown");
  out.push_back(drapegen::proto::encode(e));
  return out;
}

}  // namespace

int main(int argc, char** argv) {
  long runs = 100000;
  unsigned long seed = 1;
  for (int i = 1; i + 1 < argc; i += 2) {
    if (std::strcmp(argv[i], "--runs") == 0) runs = std::strtol(argv[i + 1], nullptr, 10);
    if (std::strcmp(argv[i], "--seed") == 0) seed = std::strtoul(argv[i + 1], nullptr, 10);
  }
  const auto seeds = corpus();
  std::mt19937_64 rng(seed);
  long decoded = 0;
  for (long run = 0; run < runs; ++run) {
    std::string input;
    const auto pick = rng() % 8;
    if (pick == 0) {  // random bytes
      input.resize(rng() % 300);
      for (auto& c : input) c = static_cast<char>(rng());
    } else {
      input = seeds[rng() % seeds.size()];
      const int mutations = 1 + static_cast<int>(rng() % 4);
      for (int m = 0; m < mutations && !input.empty(); ++m) {
        const std::size_t at = rng() % input.size();
        switch (rng() % 5) {
          case 0: input[at] = static_cast<char>(input[at] ^ (1 << (rng() % 8))); break;
          case 1: input[at] = static_cast<char>(rng()); break;
          case 2: input.resize(at); break;
          case 3: input.insert(at, 1 + rng() % 8, static_cast<char>(rng())); break;
          default: input += seeds[rng() % seeds.size()].substr(0, rng() % 20); break;
        }
      }
    }
    LLVMFuzzerTestOneInput(reinterpret_cast<const std::uint8_t*>(input.data()), input.size());
    decoded += drapegen::proto::decode(input) ? 1 : 0;
  }
  std::printf("fuzz: %ld inputs, %ld decoded as valid envelopes, no crash\n", runs, decoded);
  return 0;
}
