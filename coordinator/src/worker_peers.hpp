#pragma once
// What the coordinator and the diagnosis's fleet, the two servers of the worker protocol, tell and ask workers alike.

#include <optional>
#include <spdlog/logger.h>
#include <string>
#include <string_view>

#include "drapegen/proto/codec.hpp"

namespace drapegen::coordinator {

/// A routing id in hex, for logs.
[[nodiscard]] std::string printable(const std::string& identity);

/// Warns when a registering worker runs another build or factorises with other BLAS kernels than `self` (e.g. "this
/// coordinator"; `own_kernels` its kernels): its drapes may then differ from `others` (e.g. "the others'").
void warn_if_unlike(spdlog::logger& log, const std::string& worker, const proto::v1::Ready& ready,
                    std::string_view self, const std::string& own_kernels, std::string_view others);

/// The answer to a message from a peer that has not registered: Disconnect ("send ready"), except to a Disconnect, a
/// Shutdown or a Leave (none).
[[nodiscard]] std::optional<proto::v1::Envelope> answer_to_stranger(const proto::v1::Envelope& message);

}  // namespace drapegen::coordinator
