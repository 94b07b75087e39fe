#pragma once
// The committed model's bytes, embedded at build time (sampler/CMakeLists.txt generates the definition from
// sampler/models/vae3.dgvae). Private to drapegen::sampler.
#include <span>

namespace drapegen::sampler::detail {

[[nodiscard]] std::span<const unsigned char> builtin_model_bytes();

}  // namespace drapegen::sampler::detail
