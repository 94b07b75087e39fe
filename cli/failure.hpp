#pragma once
// How a subcommand reports that it cannot go on: one line on stderr, "drapegen COMMAND: error: MESSAGE", and the exit
// code that says what kind of failure it was.

#include <string>
#include <string_view>

#include "commands.hpp"
#include "drapegen/sim/expected.hpp"

namespace drapegen::cli {

/// Each subcommand keeps one, named after it: `const Failure fail{"simulate"}; ... return fail("bad --alpha");`
class Failure {
 public:
  explicit constexpr Failure(std::string_view command) : command_(command) {}

  /// Prints the message and returns `code`.
  int operator()(std::string_view message, int code = kExitUsage) const;
  /// A library error: kExitIo when it is an I/O error (a file that could not be read or written), else kExitUsage.
  int operator()(const sim::Error& error) const;

 private:
  std::string_view command_;
};

}  // namespace drapegen::cli
