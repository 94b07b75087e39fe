#include "worker_peers.hpp"

#include <fmt/format.h>

#include "drapegen/build_id.hpp"

namespace drapegen::coordinator {
namespace v1 = proto::v1;

std::string printable(const std::string& identity) {
  std::string out;
  for (unsigned char c : identity) out += fmt::format("{:02x}", c);
  return out;
}

void warn_if_unlike(spdlog::logger& log, const std::string& worker, const v1::Ready& ready,
                    std::string_view self, const std::string& own_kernels, std::string_view others) {
  if (const std::string& version = ready.code_version(); !version.empty() && version != DRAPEGEN_BUILD_ID) {
    log.warn("worker {} runs drapegen {}, {} {}: its drapes may differ from {}", worker, version, self,
             DRAPEGEN_BUILD_ID, others);
  }
  if (const std::string& kernels = ready.blas_kernels(); !kernels.empty() && kernels != own_kernels) {
    log.warn("worker {} factorises with {}, {} with {}: its drapes may differ from {} (OPENBLAS_CORETYPE chooses the "
             "kernels; docs/SERVICE.md, \"Determinism\")",
             worker, kernels, self, own_kernels, others);
  }
}

std::optional<v1::Envelope> answer_to_stranger(const v1::Envelope& message) {
  if (message.body_case() == v1::Envelope::kDisconnect || message.body_case() == v1::Envelope::kShutdown ||
      message.body_case() == v1::Envelope::kLeave) {
    return std::nullopt;
  }
  v1::Envelope d;
  d.mutable_disconnect()->set_reason("unknown worker: send ready");
  return d;
}

}  // namespace drapegen::coordinator
