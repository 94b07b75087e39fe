#pragma once
// Framing of the worker protocol: one Envelope per ZeroMQ frame, stamped with the protocol version on encode and
// checked on decode (docs/SERVICE.md, "Protocol").

#include <cstddef>
#include <cstdint>
#include <optional>
#include <string>
#include <string_view>
#include <utility>

#include "drapegen/proto/worker.pb.h"
#include "drapegen/sim/expected.hpp"

namespace drapegen::proto {

namespace v1 = ::drapegen::proto::v1;

/// The version this build speaks (v1::PROTOCOL_VERSION_CURRENT).
inline constexpr std::uint32_t kProtocolVersion = v1::PROTOCOL_VERSION_CURRENT;
/// Largest frame either side accepts (a drape's mesh and EXR files are far below it).
inline constexpr std::size_t kMaxFrameBytes = 256u << 20;
/// The longest heartbeat interval (ms) and the largest liveness a peer may announce (as `drapegen worker` accepts):
/// larger values would not fit the coordinator's int timers.
inline constexpr std::uint32_t kMaxHeartbeatMs = 600000;
inline constexpr std::uint32_t kMaxLiveness = 1000;
/// The longest free text a Ready may carry in each of its worker name, build id and BLAS kernels (bytes).
inline constexpr std::size_t kMaxReadyText = 256;

/// Serializes `envelope` with protocol_version set to kProtocolVersion.
[[nodiscard]] std::string encode(v1::Envelope envelope);

/// Parses one frame. Errors (one line): too large, not a valid Envelope, another protocol version, no body, or a
/// body that breaks the field rules of check().
[[nodiscard]] sim::Expected<v1::Envelope> decode(const void* data, std::size_t size);
[[nodiscard]] inline sim::Expected<v1::Envelope> decode(std::string_view frame) {
  return decode(frame.data(), frame.size());
}

/// For a frame decode() refuses: its job id and attempt if it is nonetheless a Job of this protocol version with both
/// nonzero (a job whose spec this build's checks refuse, which a worker answers as an invalid job); nothing
/// otherwise.
[[nodiscard]] std::optional<std::pair<std::uint64_t, std::uint32_t>> refused_job(const void* data, std::size_t size);

/// Field rules beyond the wire format: job ids > 0, attempts >= 1, a job spec with a known mode, a positive
/// resolution and orientation count, finite parameters, ...
[[nodiscard]] sim::Status check(const v1::Envelope& envelope);

/// The bending model a JobSpec or Metrics names: an empty field (a message from before the field existed) means the
/// paper's "dihedral"; any other value is returned as is (check() accepts "dihedral" and "triangle").
[[nodiscard]] std::string_view bending_model_name(std::string_view field);
/// JobSpec.renderer / Metrics.renderer as a renderer's name: empty (a message from before the field) is "osmesa".
[[nodiscard]] std::string_view renderer_name(std::string_view field);

/// The body's name ("ready", "job", ...; "none" without one), for logs.
[[nodiscard]] const char* body_name(const v1::Envelope& envelope);

/// The failure reason as stored in the manifest: "not_converged", "diverged", "self_intersection", "render_error",
/// "worker_lost", "timeout", "invalid_job", "worker_error" ("unspecified" otherwise: none given, or a value newer
/// than this build).
[[nodiscard]] const char* reason_name(v1::FailureReason reason);

}  // namespace drapegen::proto
