#pragma once
// Free text for protocol strings: proto3 `string` fields must hold valid UTF-8, or the receiver drops the whole
// frame (a worker's failure message naming a path in another encoding, a worker name typed on a Latin-1 terminal).

#include <cstddef>
#include <string>
#include <string_view>

namespace drapegen::proto {

/// Whether `text` is well-formed UTF-8 (no overlong forms, surrogates or code points above U+10FFFF).
[[nodiscard]] bool is_utf8(std::string_view text);

/// `text` as one line of valid UTF-8 of at most `max_bytes`: line breaks become spaces, each byte of an ill-formed
/// sequence becomes '?', and a longer text is cut at a character boundary.
[[nodiscard]] std::string one_line_utf8(std::string_view text, std::size_t max_bytes = std::string::npos);

}  // namespace drapegen::proto
