#include <gtest/gtest.h>

#include "drapegen/proto/simulation.hpp"

namespace drapegen::proto {
namespace {

/// A config that differs from DrapeConfig's defaults wherever the wire form carries a value.
sim::DrapeConfig unusual_config() {
  sim::DrapeConfig c;
  c.fabric.alpha = {1.1e-5, 2.2e-5, 3.3e-5};
  c.fabric.beta = {-1e-7, -2e-7, -3e-7};
  c.fabric.gamma = {4e-9, 5e-9, 6e-9};
  c.fabric.density = 0.217;
  c.bending_model = sim::BendingModel::kQuadratic;
  c.anisotropy = sim::AnisotropyRule::kEdge;
  c.membrane = {150.0, 0.98, 1.02, 0.02};
  c.platform = {0.051, 0.24, 0.003, 0.0012, 3e7};
  c.specimen = {0.29, 0.31, 7, 9, 0.1, sim::Triangulation::kEquilateral, 42, 0.3};
  c.initial.shape = sim::InitialShape::kFold;
  c.initial.seed = 12345678901234ULL;
  c.initial.rotation = 1.25;
  c.initial.drift = {0.004, -0.007};
  c.initial.lift = 0.002;
  c.initial.platform_radius = 0.051;
  c.solver.max_iterations = 77;
  c.solver.tolerance = 3e-3;
  c.gravity = 9.7;
  c.adhesion = false;
  c.coarse_start_resolution = 0;
  c.rest_angles = Eigen::VectorXd::LinSpaced(5, -0.1, 0.3);
  c.effects.edge_curl = sim::EdgeCurl{150.0, 0.02};
  c.effects.bending_yield_curvature = 24.0;
  c.effects.shear_stiffness = 0.8;
  c.effects.friction = sim::FrictionParameters{0.4, 2e-4};
  return c;
}

TEST(Simulation, CarriesEveryFieldOfTheConfigExactly) {
  const sim::DrapeConfig c = unusual_config();
  auto wire = to_proto(c);
  ASSERT_TRUE(wire) << wire.error().message;
  std::string bytes;
  ASSERT_TRUE(wire->SerializeToString(&bytes));
  v1::Simulation parsed;
  ASSERT_TRUE(parsed.ParseFromString(bytes));
  auto back = from_proto(parsed);
  ASSERT_TRUE(back) << back.error().message;
  const sim::DrapeConfig& b = *back;
  const auto expect_directional = [](const sim::DirectionalValues& got, const sim::DirectionalValues& sent) {
    EXPECT_EQ(got.warp, sent.warp);
    EXPECT_EQ(got.bias, sent.bias);
    EXPECT_EQ(got.weft, sent.weft);
  };
  expect_directional(b.fabric.alpha, c.fabric.alpha);
  expect_directional(b.fabric.beta, c.fabric.beta);
  expect_directional(b.fabric.gamma, c.fabric.gamma);
  EXPECT_EQ(b.fabric.density, c.fabric.density);
  EXPECT_EQ(b.bending_model, c.bending_model);
  EXPECT_EQ(b.anisotropy, c.anisotropy);
  EXPECT_EQ(b.membrane.stiffness, c.membrane.stiffness);
  EXPECT_EQ(b.membrane.band_low, c.membrane.band_low);
  EXPECT_EQ(b.membrane.band_high, c.membrane.band_high);
  EXPECT_EQ(b.membrane.band_stiffness_ratio, c.membrane.band_stiffness_ratio);
  EXPECT_EQ(b.platform.radius, c.platform.radius);
  EXPECT_EQ(b.platform.height, c.platform.height);
  EXPECT_EQ(b.platform.fillet, c.platform.fillet);
  EXPECT_EQ(b.platform.contact_offset, c.platform.contact_offset);
  EXPECT_EQ(b.platform.contact_stiffness, c.platform.contact_stiffness);
  EXPECT_EQ(b.specimen.size_x, c.specimen.size_x);
  EXPECT_EQ(b.specimen.size_y, c.specimen.size_y);
  EXPECT_EQ(b.specimen.vertices_x, c.specimen.vertices_x);
  EXPECT_EQ(b.specimen.vertices_y, c.specimen.vertices_y);
  EXPECT_EQ(b.specimen.jitter, c.specimen.jitter);
  EXPECT_EQ(b.specimen.triangulation, c.specimen.triangulation);
  EXPECT_EQ(b.specimen.seed, c.specimen.seed);
  EXPECT_EQ(b.specimen.material_angle, c.specimen.material_angle);
  EXPECT_EQ(b.initial.shape, c.initial.shape);
  EXPECT_EQ(b.initial.seed, c.initial.seed);
  EXPECT_EQ(b.initial.rotation, c.initial.rotation);
  EXPECT_EQ(b.initial.drift, c.initial.drift);
  EXPECT_EQ(b.initial.lift, c.initial.lift);
  EXPECT_EQ(b.initial.platform_radius, c.initial.platform_radius);
  EXPECT_EQ(b.solver.max_iterations, c.solver.max_iterations);
  EXPECT_EQ(b.solver.tolerance, c.solver.tolerance);
  EXPECT_EQ(b.gravity, c.gravity);
  EXPECT_EQ(b.adhesion, c.adhesion);
  EXPECT_EQ(b.coarse_start_resolution, c.coarse_start_resolution);
  EXPECT_EQ(b.rest_angles, c.rest_angles);
  ASSERT_TRUE(b.effects.edge_curl && b.effects.bending_yield_curvature && b.effects.shear_stiffness &&
              b.effects.friction);
  EXPECT_EQ(b.effects.edge_curl->curvature, c.effects.edge_curl->curvature);
  EXPECT_EQ(b.effects.edge_curl->width, c.effects.edge_curl->width);
  EXPECT_EQ(*b.effects.bending_yield_curvature, 24.0);
  EXPECT_EQ(*b.effects.shear_stiffness, 0.8);
  EXPECT_EQ(b.effects.friction->coefficient, c.effects.friction->coefficient);
  EXPECT_EQ(b.effects.friction->stick_distance, c.effects.friction->stick_distance);
  // The solver options the wire does not carry come back as DrapeConfig's (to_proto refuses others).
  EXPECT_TRUE(b.solver == c.solver);
  // An effect that is off stays off (a zero yield curvature is not "none").
  sim::DrapeConfig plain;
  plain.effects.bending_yield_curvature = 0.0;
  auto plain_back = from_proto(*to_proto(plain));
  ASSERT_TRUE(plain_back);
  EXPECT_FALSE(plain_back->effects.edge_curl || plain_back->effects.shear_stiffness || plain_back->effects.friction);
  ASSERT_TRUE(plain_back->effects.bending_yield_curvature);
  EXPECT_EQ(*plain_back->effects.bending_yield_curvature, 0.0);
}

TEST(Simulation, CarriesEveryTriangulation) {
  for (auto t : {sim::Triangulation::kAlternating, sim::Triangulation::kRandom, sim::Triangulation::kEquilateral,
                 sim::Triangulation::kUniform}) {
    sim::DrapeConfig c;
    c.specimen.triangulation = t;
    auto back = from_proto(*to_proto(c));
    ASSERT_TRUE(back) << back.error().message;
    EXPECT_EQ(back->specimen.triangulation, t);
  }
}

TEST(Simulation, RefusesWhatItCannotCarry) {
  sim::DrapeConfig mesh;
  mesh.initial.shape = sim::InitialShape::kMesh;
  mesh.initial.mesh_path = "drape.ply";
  EXPECT_FALSE(to_proto(mesh));
  sim::DrapeConfig ramped;
  ramped.load_steps = 4;
  const auto refused = to_proto(ramped);
  ASSERT_FALSE(refused);
  EXPECT_NE(refused.error().message.find("load_steps"), std::string::npos) << refused.error().message;
  sim::DrapeConfig solver;
  solver.solver.max_step = 0.02;
  EXPECT_FALSE(to_proto(solver));
  solver = {};
  solver.solver.pcg_tolerance = 0.05;  // every option, not a list of them
  EXPECT_FALSE(to_proto(solver));
  v1::Simulation s = *to_proto(sim::DrapeConfig{});
  s.set_initial_shape(3);  // kMesh
  EXPECT_FALSE(from_proto(s));
  s = *to_proto(sim::DrapeConfig{});
  s.set_specimen_triangulation(9);
  EXPECT_FALSE(from_proto(s));
  s = *to_proto(sim::DrapeConfig{});
  s.set_specimen_vertices_x(1);
  EXPECT_FALSE(from_proto(s));
  s = *to_proto(sim::DrapeConfig{});
  s.set_tolerance(0.0);
  EXPECT_FALSE(from_proto(s));
}

TEST(Simulation, CarriesADrapeAsSimulated) {
  sim::DrapeConfig c;
  c.specimen.vertices_x = c.specimen.vertices_y = 8;
  c.solver.max_iterations = 40;
  c.effects.bending_yield_curvature = 30.0;
  auto drape = sim::simulate_drape(c);
  ASSERT_TRUE(drape) << drape.error().message;
  std::string bytes;
  ASSERT_TRUE(to_proto(*drape).SerializeToString(&bytes));
  v1::SimulatedDrape parsed;
  ASSERT_TRUE(parsed.ParseFromString(bytes));
  auto back = from_proto(parsed);
  ASSERT_TRUE(back) << back.error().message;
  EXPECT_EQ(back->mesh.positions, drape->mesh.positions);
  EXPECT_EQ(back->mesh.rest, drape->mesh.rest);
  EXPECT_EQ(back->mesh.triangles, drape->mesh.triangles);
  EXPECT_EQ(back->mesh.material_angle, drape->mesh.material_angle);
  EXPECT_EQ(back->report.outcome, drape->report.outcome);
  EXPECT_EQ(back->report.iterations, drape->report.iterations);
  EXPECT_EQ(back->report.residual, drape->report.residual);
  ASSERT_GT(drape->rest_angles.size(), 0);
  EXPECT_EQ(back->rest_angles, drape->rest_angles);

  v1::SimulatedDrape broken = parsed;
  broken.mutable_positions()->RemoveLast();
  EXPECT_FALSE(from_proto(broken));
  broken = parsed;
  broken.set_triangles(0, 100000);
  EXPECT_FALSE(from_proto(broken));
  broken = parsed;
  broken.set_outcome(17);
  EXPECT_FALSE(from_proto(broken));
}

TEST(Simulation, AJobToSimulateNeedsAValidSimulation) {
  v1::Envelope e;
  e.mutable_job()->set_job_id(3);
  e.mutable_job()->set_attempt(1);
  e.mutable_job()->mutable_spec()->set_mode(v1::JOB_MODE_SIMULATE);
  EXPECT_FALSE(decode(encode(e)));  // no simulation
  *e.mutable_job()->mutable_spec()->mutable_simulation() = *to_proto(sim::DrapeConfig{});
  auto decoded = decode(encode(e));
  ASSERT_TRUE(decoded) << decoded.error().message;
  e.mutable_job()->mutable_spec()->mutable_simulation()->set_specimen_size_x(-0.3);
  EXPECT_FALSE(decode(encode(e)));
}

}  // namespace
}  // namespace drapegen::proto
