#include "drapegen/coordinator/logging.hpp"

#include <mutex>
#include <spdlog/sinks/stdout_sinks.h>

namespace drapegen::coordinator {

std::shared_ptr<spdlog::logger> logger() {
  static std::shared_ptr<spdlog::logger> instance = [] {
    auto sink = std::make_shared<spdlog::sinks::stderr_sink_mt>();
    auto log = std::make_shared<spdlog::logger>("drapegen", sink);
    log->set_pattern("[%Y-%m-%d %H:%M:%S.%e] [%l] %v");
    log->set_level(spdlog::level::info);
    log->flush_on(spdlog::level::info);
    return log;
  }();
  return instance;
}

void set_terminal_pattern(bool terminal) {
  logger()->set_pattern(terminal ? "\r\033[K[%H:%M:%S] [%l] %v" : "[%Y-%m-%d %H:%M:%S.%e] [%l] %v");
}

}  // namespace drapegen::coordinator
