#include <gtest/gtest.h>

#include <cmath>
#include <numbers>
#include <set>

#include "drapegen/sampler/initial_state_recipe.hpp"
#include "drapegen/sampler/recipe_generator.hpp"
#include "drapegen/sim/specimen.hpp"

namespace drapegen::sampler {
namespace {

std::vector<InitialStateRecipe> plan(const RecipeOptions& o, int samples) {
  std::vector<InitialStateRecipe> all;
  for (int s = 0; s < samples; ++s) {
    for (const auto& r : make_recipes_in_order(o, s)) all.push_back(r);
  }
  return all;
}

TEST(Recipes, EightPerSampleOfEveryKindWithSmallDrifts) {
  RecipeOptions o;
  o.seed = 7;
  const auto all = plan(o, 300);
  ASSERT_EQ(all.size(), 2400u);
  int counts[3] = {0, 0, 0};
  for (const auto& r : all) {
    ASSERT_TRUE(validate(r)) << to_text(r);
    ++counts[static_cast<int>(r.kind)];
    EXPECT_LE(std::hypot(r.drift_x_mm, r.drift_y_mm), o.max_drift_mm);
    if (r.kind == RecipeKind::kDrape) {
      EXPECT_LT(r.source.sample, r.sample);
      EXPECT_GE(r.source.slot, 0);
      EXPECT_LT(r.source.slot, 8);
    }
  }
  // One third each (sample 0 falls back, a negligible shift).
  for (int c : counts) EXPECT_NEAR(c, 800, 90);
  for (const auto& r : make_recipes_in_order(o, 0)) EXPECT_NE(r.kind, RecipeKind::kDrape);
}

TEST(Recipes, DeterministicAndIndependentOfOtherSamples) {
  RecipeOptions o;
  o.seed = 0;
  const auto a = plan(o, 50), b = plan(o, 50);
  EXPECT_EQ(a, b);
  // Regenerating one sample alone (a restarted coordinator) gives the same recipes.
  EXPECT_EQ(make_recipes_in_order(o, 37), std::vector<InitialStateRecipe>(a.begin() + 37 * 8, a.begin() + 38 * 8));
  o.seed = 1;
  const auto c = plan(o, 50);
  int same_seed = 0;
  for (std::size_t i = 0; i < a.size(); ++i) same_seed += a[i].shape_seed == c[i].shape_seed;
  EXPECT_EQ(same_seed, 0);
  // Triangulation and shape seeds are distinct across the plan.
  std::set<std::uint64_t> seeds;
  for (const auto& r : a) seeds.insert(r.triangulation_seed), seeds.insert(r.shape_seed);
  EXPECT_EQ(seeds.size(), 2 * a.size());
}

TEST(Recipes, ExplicitExistingDrapesMatchTheInOrderPlan) {
  RecipeOptions o;
  o.seed = 5;
  std::vector<DrapeRef> earlier;
  for (int s = 0; s < 12; ++s) {
    for (int k = 0; k < 8; ++k) earlier.push_back({s, k});
  }
  EXPECT_EQ(make_recipes(o, 12, earlier), make_recipes_in_order(o, 12));
  // With no drapes at all, the drape slots fall back to sine or fold; the other fields do not change.
  const auto none = make_recipes(o, 12, {});
  const auto some = make_recipes(o, 12, earlier);
  for (std::size_t k = 0; k < none.size(); ++k) {
    EXPECT_NE(none[k].kind, RecipeKind::kDrape);
    EXPECT_EQ(none[k].shape_seed, some[k].shape_seed);
    EXPECT_EQ(none[k].drift_x_mm, some[k].drift_x_mm);
  }
  // The sample's own drapes are never its source.
  const std::vector<DrapeRef> own{{12, 0}, {12, 1}, {3, 4}};
  for (const auto& r : make_recipes(o, 12, own)) {
    if (r.kind == RecipeKind::kDrape) {
      EXPECT_EQ(r.source, (DrapeRef{3, 4}));
    }
  }
}

TEST(Recipes, TextAndJsonRoundTripBitForBit) {
  RecipeOptions o;
  o.seed = 11;
  for (const auto& r : plan(o, 40)) {
    auto from_text = parse_recipe_text(to_text(r));
    ASSERT_TRUE(from_text) << from_text.error().message << ": " << to_text(r);
    EXPECT_EQ(*from_text, r);
    auto from_json = recipe_from_json(nlohmann::json::parse(to_json(r).dump()));
    ASSERT_TRUE(from_json) << from_json.error().message;
    EXPECT_EQ(*from_json, r);
  }
  InitialStateRecipe r;
  r.sample = 12, r.slot = 3, r.kind = RecipeKind::kDrape, r.shape_seed = 18446744073709551615ULL;
  r.rotation = 1.25, r.drift_x_mm = 0.5, r.drift_y_mm = -1.75, r.source = {7, 2};
  EXPECT_EQ(to_text(r),
            "sample=12 slot=3 kind=drape shape_seed=18446744073709551615 triangulation_seed=0 rotation=1.25 "
            "drift_mm=0.5,-1.75 source=7/2");
  EXPECT_EQ(to_json(r).dump(),
            R"({"drift_mm":[0.5,-1.75],"kind":"drape","rotation":1.25,"sample":12,"shape_seed":18446744073709551615,)"
            R"("slot":3,"source":{"sample":7,"slot":2},"triangulation_seed":0})");
}

TEST(Recipes, MalformedFormsAreErrors) {
  for (const char* text :
       {"", "sample=1", "slot=0 sample=1 kind=sine shape_seed=1 triangulation_seed=2 rotation=0 drift_mm=0,0 source=-",
        "sample=1 slot=0 kind=wavy shape_seed=1 triangulation_seed=2 rotation=0 drift_mm=0,0 source=-",
        "sample=1 slot=0 kind=sine shape_seed=-1 triangulation_seed=2 rotation=0 drift_mm=0,0 source=-",
        "sample=1 slot=0 kind=sine shape_seed=1 triangulation_seed=2 rotation=7 drift_mm=0,0 source=-",
        "sample=1 slot=0 kind=sine shape_seed=1 triangulation_seed=2 rotation=0 drift_mm=0 source=-",
        "sample=1 slot=0 kind=sine shape_seed=1 triangulation_seed=2 rotation=0 drift_mm=0,0 source=0/1",
        "sample=1 slot=0 kind=drape shape_seed=1 triangulation_seed=2 rotation=0 drift_mm=0,0 source=-",
        "sample=1 slot=0 kind=drape shape_seed=1 triangulation_seed=2 rotation=0 drift_mm=0,0 source=1/1",
        "sample=1 slot=0 kind=sine shape_seed=1 triangulation_seed=2 rotation=0 drift_mm=0,0 source=- extra=1"}) {
    EXPECT_FALSE(parse_recipe_text(text)) << text;
  }
  EXPECT_FALSE(recipe_from_json(nlohmann::json::parse("[1,2]")));
  EXPECT_FALSE(recipe_from_json(nlohmann::json::parse(R"({"sample":1})")));
  EXPECT_FALSE(recipe_from_json(nlohmann::json::parse(
      R"({"sample":1,"slot":0,"kind":"sine","shape_seed":-3,"triangulation_seed":0,"rotation":0,"drift_mm":[0,0],"source":null})")));
}

TEST(Recipes, BecomeTheSimulatorsInitialState) {
  RecipeOptions o;
  o.seed = 2;
  for (const auto& r : plan(o, 10)) {
    auto spec = to_initial_state(r, [](const DrapeRef& d) {
      return "drapes/" + std::to_string(d.sample) + "_" + std::to_string(d.slot) + ".ply";
    });
    ASSERT_TRUE(spec) << spec.error().message;
    EXPECT_EQ(spec->seed, r.shape_seed);
    EXPECT_EQ(spec->rotation, r.rotation);
    EXPECT_DOUBLE_EQ(spec->drift.x(), r.drift_x_mm * 1e-3);
    if (r.kind == RecipeKind::kDrape) {
      EXPECT_EQ(spec->shape, sim::InitialShape::kMesh);
      EXPECT_EQ(spec->mesh_path,
                "drapes/" + std::to_string(r.source.sample) + "_" + std::to_string(r.source.slot) + ".ply");
      EXPECT_FALSE(to_initial_state(r));  // no locator
    } else {
      EXPECT_EQ(spec->shape, r.kind == RecipeKind::kSine ? sim::InitialShape::kSine : sim::InitialShape::kFold);
      // Replaying the recipe twice builds the same initial mesh, bit for bit.
      sim::SpecimenSpec specimen{0.3, 0.3, 12, 12, 0.2, sim::Triangulation::kRandom, 0, 0.0};
      apply_triangulation(r, specimen);
      EXPECT_EQ(specimen.seed, r.triangulation_seed);
      sim::ClothMesh a = sim::make_specimen(specimen), b = sim::make_specimen(specimen);
      ASSERT_TRUE(sim::apply_initial_state(*spec, a));
      ASSERT_TRUE(sim::apply_initial_state(*spec, b));
      EXPECT_EQ((a.positions - b.positions).cwiseAbs().maxCoeff(), 0.0);
    }
  }
}

TEST(Recipes, BadOptionsAreErrors) {
  RecipeOptions o;
  EXPECT_TRUE(validate(o));
  o.states_per_sample = 0;
  EXPECT_FALSE(validate(o));
  o = {};
  o.weight_sine = o.weight_fold = 0.0;
  EXPECT_FALSE(validate(o));
  o = {};
  o.max_drift_mm = -1;
  EXPECT_FALSE(validate(o));
}

}  // namespace
}  // namespace drapegen::sampler
