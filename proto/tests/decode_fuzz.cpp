// Fuzz target of the message decoding (libFuzzer's entry point; tests/fuzz_driver.cpp drives it without libFuzzer).
// Whatever the bytes, decode() returns a value or an error: no crash, no exception, no hang; a decoded envelope
// re-encodes and decodes to an equal message.
#include <cstdint>
#include <cstdlib>
#include <google/protobuf/util/message_differencer.h>

#include "drapegen/proto/codec.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const auto decoded = drapegen::proto::decode(data, size);
  if (decoded) {
    const auto again = drapegen::proto::decode(drapegen::proto::encode(*decoded));
    if (!again || !google::protobuf::util::MessageDifferencer::Equals(*decoded, *again)) std::abort();
  }
  return 0;
}
