#include <gtest/gtest.h>

#include <cmath>

#include "drapegen/proto/codec.hpp"

namespace drapegen::proto {
namespace {

v1::Envelope valid_job() {
  v1::Envelope e;
  auto* job = e.mutable_job();
  job->set_job_id(7);
  job->set_attempt(1);
  job->set_lease_ms(1000);
  auto* s = job->mutable_spec();
  s->set_mode(v1::JOB_MODE_DRAPE);
  s->set_resolution(15);
  s->set_orientations(1);
  s->set_noise("kinect");
  s->set_max_iterations(100);
  s->set_tolerance(1e-3);
  auto* p = s->mutable_parameters();
  p->set_alpha_warp(1e4);
  p->set_alpha_bias(1e4);
  p->set_alpha_weft(1e4);
  p->set_density_g_per_m2(300);
  s->mutable_recipe()->set_kind(v1::Recipe::KIND_SINE);
  return e;
}

TEST(Codec, RoundTripsAJob) {
  const std::string frame = encode(valid_job());
  const auto decoded = decode(frame);
  ASSERT_TRUE(decoded) << decoded.error().message;
  EXPECT_EQ(decoded->protocol_version(), kProtocolVersion);
  EXPECT_EQ(decoded->job().job_id(), 7u);
  EXPECT_EQ(decoded->job().spec().resolution(), 15);
  EXPECT_STREQ(body_name(*decoded), "job");
}

TEST(Codec, RejectsAnotherVersion) {
  v1::Envelope e = valid_job();
  e.set_protocol_version(2);
  std::string frame;
  e.SerializeToString(&frame);
  const auto decoded = decode(frame);
  ASSERT_FALSE(decoded);
  EXPECT_NE(decoded.error().message.find("protocol version 2"), std::string::npos);
  e.set_protocol_version(0);
  e.SerializeToString(&frame);
  EXPECT_FALSE(decode(frame));
}

TEST(Codec, RejectsGarbageTruncationAndEmptyBodies) {
  EXPECT_FALSE(decode(std::string("\xff\xff\xff\xff garbage", 12)));
  const std::string frame = encode(valid_job());
  int rejected = 0;
  for (std::size_t n = 0; n < frame.size(); ++n) rejected += !decode(frame.substr(0, n));
  EXPECT_EQ(rejected, static_cast<int>(frame.size()));  // every strict prefix fails (parse, version or rules)
  v1::Envelope empty;
  EXPECT_FALSE(decode(encode(empty)));
}

// A job whose spec this build refuses still names its job and attempt, so a worker can answer it as an invalid job
// instead of leaving its lease held until it expires; nothing else does (another version, no ids, another body).
TEST(Codec, ARefusedJobStillNamesItsJobAndAttempt) {
  v1::Envelope e = valid_job();
  e.mutable_job()->set_attempt(3);
  e.mutable_job()->mutable_spec()->set_resolution(2);
  std::string frame = encode(e);
  ASSERT_FALSE(decode(frame));
  const auto refused = refused_job(frame.data(), frame.size());
  ASSERT_TRUE(refused);
  EXPECT_EQ(refused->first, 7u);
  EXPECT_EQ(refused->second, 3u);
  e.set_protocol_version(2);
  e.SerializeToString(&frame);
  EXPECT_FALSE(refused_job(frame.data(), frame.size()));
  e = valid_job();
  e.mutable_job()->set_job_id(0);
  frame = encode(e);
  EXPECT_FALSE(refused_job(frame.data(), frame.size()));
  v1::Envelope heartbeat;
  heartbeat.mutable_heartbeat()->set_interval_ms(kMaxHeartbeatMs + 1);
  frame = encode(heartbeat);
  EXPECT_FALSE(decode(frame));
  EXPECT_FALSE(refused_job(frame.data(), frame.size()));
  EXPECT_FALSE(refused_job("\xff\xff garbage", 10));
}

TEST(Codec, ChecksFieldRules) {
  v1::Envelope e = valid_job();
  e.mutable_job()->mutable_spec()->mutable_parameters()->set_alpha_bias(std::nan(""));
  EXPECT_FALSE(decode(encode(e)));
  e = valid_job();
  e.mutable_job()->mutable_spec()->set_resolution(2);
  EXPECT_FALSE(decode(encode(e)));
  e = valid_job();
  e.mutable_job()->set_attempt(0);
  EXPECT_FALSE(decode(encode(e)));
  e = valid_job();
  e.mutable_job()->mutable_spec()->set_renderer("vulkan");
  EXPECT_FALSE(decode(encode(e)));
  for (const char* renderer : {"", "osmesa", "software"}) {  // empty: a job from before the field, OSMesa
    e.mutable_job()->mutable_spec()->set_renderer(renderer);
    EXPECT_TRUE(decode(encode(e))) << renderer;
  }
  e = valid_job();
  e.mutable_job()->mutable_spec()->set_bending_model("quadratic");
  EXPECT_FALSE(decode(encode(e)));
  for (const char* model : {"", "dihedral", "triangle"}) {  // empty: a job from before the field, the paper's model
    e.mutable_job()->mutable_spec()->set_bending_model(model);
    EXPECT_TRUE(decode(encode(e))) << model;
  }
  EXPECT_EQ(bending_model_name(""), "dihedral");  // the one place that rule is spelled (worker, coordinator use it)
  EXPECT_EQ(bending_model_name("triangle"), "triangle");
  EXPECT_EQ(bending_model_name("quadratic"), "quadratic");
  v1::Envelope f;
  f.mutable_failure()->set_job_id(3);
  f.mutable_failure()->set_attempt(1);
  EXPECT_TRUE(decode(encode(f)));  // no reason: still a failure of its job, recorded as "unspecified"
  EXPECT_STREQ(reason_name(f.failure().reason()), "unspecified");
  f.mutable_failure()->set_reason(static_cast<v1::FailureReason>(42));  // a newer build's reason
  EXPECT_TRUE(decode(encode(f)));
  EXPECT_STREQ(reason_name(f.failure().reason()), "unspecified");
  f.mutable_failure()->set_reason(v1::FAILURE_REASON_DIVERGED);
  EXPECT_TRUE(decode(encode(f)));
  EXPECT_STREQ(reason_name(v1::FAILURE_REASON_DIVERGED), "diverged");
  // A Leave names a job by id and attempt, or none; its reason is bounded like a Ready's text.
  v1::Envelope l;
  l.mutable_leave()->set_reason("stopped");
  EXPECT_TRUE(decode(encode(l)));
  EXPECT_STREQ(body_name(l), "leave");
  l.mutable_leave()->set_job_id(3);
  EXPECT_FALSE(decode(encode(l)));
  l.mutable_leave()->set_attempt(2);
  EXPECT_TRUE(decode(encode(l)));
  l.mutable_leave()->set_reason(std::string(kMaxReadyText + 1, 'x'));
  EXPECT_FALSE(decode(encode(l)));
  // Heartbeat intervals and liveness within what `drapegen worker` accepts (beyond, they overflow int timers).
  v1::Envelope h;
  h.mutable_heartbeat()->set_interval_ms(kMaxHeartbeatMs);
  h.mutable_heartbeat()->set_liveness(kMaxLiveness);
  EXPECT_TRUE(decode(encode(h)));
  h.mutable_heartbeat()->set_interval_ms(kMaxHeartbeatMs + 1);
  EXPECT_FALSE(decode(encode(h)));
  h.mutable_heartbeat()->set_interval_ms(100);
  h.mutable_heartbeat()->set_liveness(kMaxLiveness + 1);
  EXPECT_FALSE(decode(encode(h)));
  v1::Envelope r;
  r.mutable_ready()->set_interval_ms(kMaxHeartbeatMs);
  EXPECT_TRUE(decode(encode(r)));
  r.mutable_ready()->set_interval_ms(0x80000000u);  // negative as an int
  EXPECT_FALSE(decode(encode(r)));
  // Its free text (logged) is bounded: kMaxReadyText bytes pass, one more does not, in each field.
  const std::string longest(kMaxReadyText, 'x'), too_long(kMaxReadyText + 1, 'x');
  using Setter = void (*)(v1::Ready&, const std::string&);
  for (Setter set : {Setter{[](v1::Ready& m, const std::string& v) { m.set_worker_name(v); }},
                     Setter{[](v1::Ready& m, const std::string& v) { m.set_code_version(v); }},
                     Setter{[](v1::Ready& m, const std::string& v) { m.set_blas_kernels(v); }}}) {
    v1::Envelope t;
    set(*t.mutable_ready(), longest);
    EXPECT_TRUE(decode(encode(t)));
    set(*t.mutable_ready(), too_long);
    EXPECT_FALSE(decode(encode(t)));
  }
}

}  // namespace
}  // namespace drapegen::proto
