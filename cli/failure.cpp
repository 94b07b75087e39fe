#include "failure.hpp"

#include <iostream>

namespace drapegen::cli {

int Failure::operator()(std::string_view message, int code) const {
  std::cerr << "drapegen " << command_ << ": error: " << message << "\n";
  return code;
}

int Failure::operator()(const sim::Error& error) const {
  return (*this)(error.message, error.io ? kExitIo : kExitUsage);
}

}  // namespace drapegen::cli
