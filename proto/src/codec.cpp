#include "drapegen/proto/codec.hpp"

#include "drapegen/proto/simulation.hpp"

#include <cmath>
#include <fmt/format.h>
#include <google/protobuf/stubs/logging.h>
#include <mutex>

namespace drapegen::proto {
namespace {

sim::Status check_parameters(const v1::Parameters& p) {
  const double values[] = {p.alpha_warp(), p.alpha_bias(), p.alpha_weft(), p.beta_warp(),
                           p.beta_bias(),  p.beta_weft(),  p.density_g_per_m2()};
  for (double v : values) {
    if (!std::isfinite(v)) return sim::Error{"job: non-finite parameter"};
  }
  if (!(p.alpha_warp() > 0 && p.alpha_bias() > 0 && p.alpha_weft() > 0)) return sim::Error{"job: alpha must be > 0"};
  if (!(p.density_g_per_m2() > 0)) return sim::Error{"job: density must be > 0"};
  return {};
}

sim::Status check_spec(const v1::JobSpec& s) {
  if (s.mode() != v1::JOB_MODE_DRAPE && s.mode() != v1::JOB_MODE_NOOP && s.mode() != v1::JOB_MODE_POISON &&
      s.mode() != v1::JOB_MODE_SIMULATE) {
    return sim::Error{fmt::format("job: unknown mode {}", static_cast<int>(s.mode()))};
  }
  if (s.mode() == v1::JOB_MODE_NOOP) return {};
  if (s.mode() == v1::JOB_MODE_SIMULATE) {
    if (!s.has_simulation()) return sim::Error{"job: simulate without a simulation"};
    if (auto config = from_proto(s.simulation()); !config) return sim::Error{"job: " + config.error().message};
    return {};
  }
  if (s.resolution() < 3 || s.resolution() > 1000) return sim::Error{"job: resolution outside 3..1000"};
  if (s.orientations() < 1 || s.orientations() > 360) return sim::Error{"job: orientations outside 1..360"};
  if (s.noise() != "kinect" && s.noise() != "none") return sim::Error{"job: noise must be kinect or none"};
  if (!s.renderer().empty() && s.renderer() != "osmesa" && s.renderer() != "software") {
    return sim::Error{"job: renderer must be osmesa or software"};
  }
  if (const auto model = bending_model_name(s.bending_model()); model != "dihedral" && model != "triangle") {
    return sim::Error{"job: bending_model must be dihedral or triangle"};
  }
  if (s.max_iterations() < 1) return sim::Error{"job: max_iterations must be >= 1"};
  if (!(s.tolerance() > 0) || !std::isfinite(s.tolerance())) return sim::Error{"job: tolerance must be > 0"};
  if (s.max_self_intersections() < 0) return sim::Error{"job: max_self_intersections must be >= 0"};
  if (s.coarse_start_resolution() < 0) return sim::Error{"job: coarse_start_resolution must be >= 0"};
  if (sim::Status st = check_parameters(s.parameters()); !st) return st;
  const auto& r = s.recipe();
  if (r.sample() < 0 || r.slot() < 0) return sim::Error{"job: negative sample or slot"};
  if (r.kind() != v1::Recipe::KIND_SINE && r.kind() != v1::Recipe::KIND_FOLD && r.kind() != v1::Recipe::KIND_DRAPE) {
    return sim::Error{"job: unknown recipe kind"};
  }
  if (!std::isfinite(r.rotation()) || !std::isfinite(r.drift_x_mm()) || !std::isfinite(r.drift_y_mm())) {
    return sim::Error{"job: non-finite recipe value"};
  }
  return {};
}

}  // namespace

std::string encode(v1::Envelope envelope) {
  envelope.set_protocol_version(kProtocolVersion);
  std::string out;
  envelope.SerializeToString(&out);
  return out;
}

sim::Expected<v1::Envelope> decode(const void* data, std::size_t size) {
  // Hostile input must not flood stderr: libprotobuf logs every invalid UTF-8 string it parses.
  static std::once_flag quiet;
  std::call_once(quiet, [] { google::protobuf::SetLogHandler(nullptr); });
  if (size > kMaxFrameBytes) return sim::Error{fmt::format("frame of {} bytes is too large", size)};
  v1::Envelope envelope;
  if (!envelope.ParseFromArray(data, static_cast<int>(size))) return sim::Error{"frame is not a protocol envelope"};
  if (envelope.protocol_version() != kProtocolVersion) {
    return sim::Error{fmt::format("protocol version {} (this build speaks {})", envelope.protocol_version(),
                                  kProtocolVersion)};
  }
  if (envelope.body_case() == v1::Envelope::BODY_NOT_SET) return sim::Error{"envelope without a body"};
  if (sim::Status s = check(envelope); !s) return s.error();
  return envelope;
}

std::optional<std::pair<std::uint64_t, std::uint32_t>> refused_job(const void* data, std::size_t size) {
  v1::Envelope envelope;
  if (size > kMaxFrameBytes || !envelope.ParseFromArray(data, static_cast<int>(size))) return std::nullopt;
  if (envelope.protocol_version() != kProtocolVersion || envelope.body_case() != v1::Envelope::kJob) {
    return std::nullopt;
  }
  if (envelope.job().job_id() == 0 || envelope.job().attempt() == 0) return std::nullopt;
  return std::pair{envelope.job().job_id(), envelope.job().attempt()};
}

sim::Status check(const v1::Envelope& e) {
  switch (e.body_case()) {
    case v1::Envelope::kReady:
      // Free text that goes into logs (and the manifest): bounded.
      if (e.ready().worker_name().size() > kMaxReadyText) return sim::Error{"ready: worker name too long"};
      if (e.ready().code_version().size() > kMaxReadyText) return sim::Error{"ready: code version too long"};
      if (e.ready().blas_kernels().size() > kMaxReadyText) return sim::Error{"ready: BLAS kernels too long"};
      if (e.ready().interval_ms() > kMaxHeartbeatMs) return sim::Error{"ready: heartbeat interval too long"};
      return {};
    case v1::Envelope::kJob:
      if (e.job().job_id() == 0) return sim::Error{"job: id 0"};
      if (e.job().attempt() == 0) return sim::Error{"job: attempt 0"};
      return check_spec(e.job().spec());
    case v1::Envelope::kHeartbeat:
      if (e.heartbeat().interval_ms() > kMaxHeartbeatMs) return sim::Error{"heartbeat: interval too long"};
      if (e.heartbeat().liveness() > kMaxLiveness) return sim::Error{"heartbeat: liveness too large"};
      return {};
    case v1::Envelope::kResult:
      if (e.result().job_id() == 0) return sim::Error{"result: job id 0"};
      if (e.result().attempt() == 0) return sim::Error{"result: attempt 0"};
      return {};
    case v1::Envelope::kFailure:
      if (e.failure().job_id() == 0) return sim::Error{"failure: job id 0"};
      if (e.failure().attempt() == 0) return sim::Error{"failure: attempt 0"};
      // Any reason passes, none or one newer than this build included: dropping the failure would leave its job
      // leased until the lease expires (the coordinator records it as "unspecified", with its number).
      return {};
    case v1::Envelope::kLeave:
      // Both or neither: a job is named by its id and attempt.
      if ((e.leave().job_id() == 0) != (e.leave().attempt() == 0)) return sim::Error{"leave: job id without attempt"};
      if (e.leave().reason().size() > kMaxReadyText) return sim::Error{"leave: reason too long"};
      return {};
    case v1::Envelope::kDisconnect:
    case v1::Envelope::kShutdown:
      return {};
    case v1::Envelope::BODY_NOT_SET:
      break;
  }
  return sim::Error{"envelope without a body"};
}

std::string_view bending_model_name(std::string_view field) { return field.empty() ? "dihedral" : field; }

std::string_view renderer_name(std::string_view field) { return field.empty() ? "osmesa" : field; }

const char* body_name(const v1::Envelope& e) {
  switch (e.body_case()) {
    case v1::Envelope::kReady: return "ready";
    case v1::Envelope::kJob: return "job";
    case v1::Envelope::kHeartbeat: return "heartbeat";
    case v1::Envelope::kResult: return "result";
    case v1::Envelope::kFailure: return "failure";
    case v1::Envelope::kDisconnect: return "disconnect";
    case v1::Envelope::kShutdown: return "shutdown";
    case v1::Envelope::kLeave: return "leave";
    case v1::Envelope::BODY_NOT_SET: break;
  }
  return "none";
}

const char* reason_name(v1::FailureReason reason) {
  switch (reason) {
    case v1::FAILURE_REASON_NOT_CONVERGED: return "not_converged";
    case v1::FAILURE_REASON_DIVERGED: return "diverged";
    case v1::FAILURE_REASON_SELF_INTERSECTION: return "self_intersection";
    case v1::FAILURE_REASON_RENDER_ERROR: return "render_error";
    case v1::FAILURE_REASON_WORKER_LOST: return "worker_lost";
    case v1::FAILURE_REASON_TIMEOUT: return "timeout";
    case v1::FAILURE_REASON_INVALID_JOB: return "invalid_job";
    case v1::FAILURE_REASON_WORKER_ERROR: return "worker_error";
    default: break;
  }
  return "unspecified";
}

}  // namespace drapegen::proto
