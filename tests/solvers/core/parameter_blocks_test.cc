// The parameter blocks' layout, starting values, bounds and validation
// messages (their derivatives: parameter_block_derivatives_test.cc).
#include <gtest/gtest.h>

#include <limits>

#include "diffpd/error.h"
#include "util/expect_message.h"
#include "solvers/core/parameter_block_cases.h"

namespace diffpd::testing {
namespace {

using namespace solvers;

TEST(ParameterBlocksTest, BoundsAndStartingValuesAreValidated) {
  InitialStateBlock v0(InitialStateBlock::kVelocity, {1, 2});
  EXPECT_EQ(v0.size(), 3);
  EXPECT_EQ(v0.lower()(0), -std::numeric_limits<double>::infinity());
  v0.SetBounds(1, 2, -1.0, 2.0);
  EXPECT_EQ(v0.lower(), Eigen::Vector3d(-std::numeric_limits<double>::infinity(), -1, -1));
  EXPECT_EQ(v0.upper()(2), 2.0);
  EXPECT_EQ(MessageOf<InvalidInputError>([&] { v0.SetBounds(2, 2, 0, 1); }),
            "initial_velocity: bounds for variables [2, 4) are out of range [0, 3)");
  EXPECT_EQ(MessageOf<InvalidInputError>([&] { v0.SetBounds(1, 0); }),
            "initial_velocity: bounds [1, 0] are invalid: need lower <= upper, no NaN");
  EXPECT_EQ(MessageOf<InvalidInputError>([&] { v0.SetInitial(VectorXd::Zero(2)); }),
            "initial_velocity: starting values have 2 entries (expected 3, all finite)");
  EXPECT_EQ(MessageOf<InvalidInputError>([] { InitialStateBlock(InitialStateBlock::kPosition, {}); }),
            "initial_position: the node list is empty");
  EXPECT_EQ(MessageOf<InvalidInputError>([] {
              InitialStateBlock(InitialStateBlock::kPosition, {3, -1});
            }),
            "initial_position: node -1 is invalid: must be >= 0");
  EXPECT_EQ(InitialStateBlock(InitialStateBlock::kPosition, {3, 4, 5}, InitialStateBlock::kPerNode).size(), 9);
}

TEST(ParameterBlocksTest, MaterialBlockListsBaseAndRegionFieldsScaled) {
  const Scene scene = TwoRegionBeamScene();
  MaterialBlock block({{MaterialField::kYoungsModulus, kBaseMaterial, 1e5},
                       MaterialField::kPoissonsRatio,
                       {MaterialField::kYoungsModulus, 0, 1e4},
                       {MaterialField::kDensity, 1, 1e3}},
                      scene);
  EXPECT_EQ(block.initial(), Eigen::Vector4d(scene.material.youngs_modulus / 1e5, scene.material.poissons_ratio,
                                             scene.material_regions[0].material.youngs_modulus / 1e4,
                                             scene.material_regions[1].material.density / 1e3));
  RolloutSetup setup;
  setup.material = scene.material;
  setup.region_materials = {scene.material_regions[0].material, scene.material_regions[1].material};
  block.Apply(Eigen::Vector4d(3, 0.2, 5, 0.7), &setup);
  EXPECT_EQ(setup.material.youngs_modulus, 3e5);
  EXPECT_EQ(setup.material.poissons_ratio, 0.2);
  EXPECT_EQ(setup.material.density, scene.material.density);
  EXPECT_EQ(setup.region_materials[0].youngs_modulus, 5e4);
  EXPECT_EQ(setup.region_materials[0].poissons_ratio, scene.material_regions[0].material.poissons_ratio);
  EXPECT_EQ(setup.region_materials[1].density, 700);
  EXPECT_EQ(MessageOf<InvalidInputError>([&] { MaterialBlock({}, scene); }), "material: no parameter");
  EXPECT_EQ(MessageOf<InvalidInputError>([&] {
              MaterialBlock({{MaterialField::kDensity, kBaseMaterial, 0.0}}, scene);
            }),
            "material: entry 0: scale = 0 is invalid: must be finite and > 0");
  EXPECT_EQ(MessageOf<InvalidInputError>([&] {
              MaterialBlock({MaterialField::kDensity, {MaterialField::kDensity, 2}}, scene);
            }),
            "material: entry 1: region 2 is out of range [0, 2)");
  EXPECT_EQ(MessageOf<InvalidInputError>([&] {
              MaterialBlock({{MaterialField::kDensity, -2}}, scene);
            }),
            "material: entry 0: region -2 is out of range [0, 2)");
  EXPECT_EQ(MessageOf<InvalidInputError>([&] {
              MaterialBlock({{MaterialField::kYoungsModulus, 1},
                             {MaterialField::kYoungsModulus, 0},
                             {MaterialField::kYoungsModulus, 1}},
                            scene);
            }),
            "material: entry 2 lists youngs_modulus of region 1 again");
  EXPECT_EQ(MessageOf<InvalidInputError>([&] {
              MaterialBlock({MaterialField::kDensity, MaterialField::kDensity}, scene);
            }),
            "material: entry 1 lists density of the base material again");
  // A block made for a scene with regions does not fit one without.
  RolloutFunction f(SmallBeamScene(), TightOptions(Method::kNewtonCholesky), 2);
  EXPECT_EQ(MessageOf<InvalidInputError>([&] {
              f.AddBlock(std::make_unique<MaterialBlock>(
                  std::vector<MaterialBlock::Entry>{{MaterialField::kDensity, 1}}, scene));
            }),
            "material: entry 0: region 1 is out of range [0, 0)");
}

TEST(ParameterBlocksTest, StateForceBlockNeedsDeclaredTerms) {
  ParameterBlockCase c = StateForceCase();
  const Scene& scene = c.function->scene();
  const StateForceBlock& block = dynamic_cast<const StateForceBlock&>(c.function->block(1));
  EXPECT_EQ(block.initial()(0), *scene.linear_damping);
  EXPECT_EQ(block.initial()(1), scene.hydrodynamics->fluid_density / 1e3);
  EXPECT_EQ(block.initial()(8), scene.penalty_contacts[0].friction);
  EXPECT_TRUE(block.SupportsForwardMode());
  const Scene plain = SmallBeamScene();
  EXPECT_EQ(MessageOf<InvalidInputError>([&] { StateForceBlock({}, scene); }), "state_forces: no parameter");
  EXPECT_EQ(MessageOf<InvalidInputError>([&] { StateForceBlock({StateForceField::kLinearDamping}, plain); }),
            "state_forces: entry 0: linear_damping is not declared by the scene");
  EXPECT_EQ(MessageOf<InvalidInputError>([&] { StateForceBlock({StateForceField::kThrust}, plain); }),
            "state_forces: entry 0: thrust is not declared by the scene (it has no hydrodynamics)");
  EXPECT_EQ(MessageOf<InvalidInputError>([&] {
              StateForceBlock({{StateForceField::kThrust, -1.0}}, scene);
            }),
            "state_forces: entry 0: scale = -1 is invalid: must be finite and > 0");
  EXPECT_EQ(MessageOf<InvalidInputError>([&] {
              StateForceBlock({StateForceField::kThrust, {StateForceField::kPenaltyFriction, 1, 3}}, scene);
            }),
            "state_forces: entry 1: penalty contact 3 is out of range [0, 1)");
  EXPECT_EQ(MessageOf<InvalidInputError>([&] {
              StateForceBlock({StateForceField::kDragNormal, StateForceField::kDragNormal}, scene);
            }),
            "state_forces: entry 1 lists drag_normal again");
  Scene frictionless = scene;
  frictionless.penalty_contacts[0].friction = 0;
  EXPECT_EQ(MessageOf<InvalidInputError>([&] { StateForceBlock({StateForceField::kPenaltyFriction}, frictionless); }),
            "state_forces: entry 0: penalty contact 0 has friction 0: a fitted friction must start > 0");
}

TEST(ParameterBlocksTest, LinearInputBlockChecksItsBases) {
  EXPECT_EQ(MessageOf<InvalidInputError>([] { LinearInputBlock(MatrixXd(), MatrixXd()); }),
            "linear_input: no basis with at least one column given");
  EXPECT_EQ(MessageOf<InvalidInputError>([] { LinearInputBlock(MatrixXd::Zero(6, 2), MatrixXd::Zero(6, 3)); }),
            "velocity_basis has 3 columns, but another basis has 2");
  EXPECT_EQ(MessageOf<InvalidInputError>([] { LinearInputBlock(MatrixXd::Zero(7, 1), MatrixXd()); }),
            "position_basis has 7 rows, expected 3 x number of nodes");
  EXPECT_EQ(MessageOf<InvalidInputError>([] { LinearInputBlock(MatrixXd(), MatrixXd(), MatrixXd::Zero(6, 1), 3, 2); }),
            "force_begin = 3, force_end = 2 is invalid: need 0 <= begin <= end");
  RolloutFunction f(SmallBeamScene(), TightOptions(Method::kNewtonCholesky), 2);
  EXPECT_EQ(MessageOf<InvalidInputError>(
                [&] { f.AddBlock(std::make_unique<LinearInputBlock>(MatrixXd::Zero(6, 1), MatrixXd())); }),
            "linear_input: a basis has 6 rows but the scene has 135 DoFs");
  // The force acts from state begin + 1 on; a column with no entry affects nothing.
  MatrixXd force = MatrixXd::Zero(135, 2);
  force(134, 0) = 1;
  const LinearInputBlock late(MatrixXd(), MatrixXd(), force, 2, 5);
  EXPECT_EQ(late.FirstAffectedState(0), 3);
  EXPECT_EQ(late.FirstAffectedState(1), kAffectsNoState);
}

TEST(ParameterBlocksTest, SignalBlocksCheckTheirChannels) {
  std::vector<ExternalForceBlock::Channel> forces(2);
  forces[0] = {{1, 2}, Vec3::UnitZ(), std::make_unique<PerStepSignal>(4)};
  forces[1] = {{3}, Vec3::UnitY(), std::make_unique<PiecewiseLinearSignal>(5, 2)};
  EXPECT_EQ(MessageOf<InvalidInputError>([&] { ExternalForceBlock(std::move(forces)); }),
            "external_force channel 1: its signal has 5 steps, channel 0's has 4");
  std::vector<ExternalForceBlock::Channel> no_signal(1);
  no_signal[0] = {{1}, Vec3::UnitZ(), nullptr};
  EXPECT_EQ(MessageOf<InvalidInputError>([&] { ExternalForceBlock(std::move(no_signal)); }),
            "external_force channel 0: no signal");
  EXPECT_EQ(MessageOf<InvalidInputError>([] { ExternalForceBlock({}); }), "external_force: no channel");
  std::vector<ActivationBlock::Channel> twice(2);
  twice[0] = {0, std::make_unique<PerStepSignal>(4)};
  twice[1] = {0, std::make_unique<PerStepSignal>(4)};
  EXPECT_EQ(MessageOf<InvalidInputError>([&] { ActivationBlock(std::move(twice)); }),
            "activation channel 1: muscle 0 is already driven by channel 0");
  std::vector<ActivationBlock::Channel> one(1);
  one[0] = {4, std::make_unique<PerStepSignal>(3)};
  ParameterBlockCase c = ActivationCase();  // 2 muscles, 5 steps
  EXPECT_EQ(
      MessageOf<InvalidInputError>([&] { c.function->AddBlock(std::make_unique<ActivationBlock>(std::move(one))); }),
      "activation channel 0: muscle 4 is out of range: the scene has 2 muscles");
  std::vector<ActivationBlock::Channel> short_signal(1);
  short_signal[0] = {1, std::make_unique<PerStepSignal>(3)};
  EXPECT_EQ(MessageOf<InvalidInputError>(
                [&] { c.function->AddBlock(std::make_unique<ActivationBlock>(std::move(short_signal))); }),
            "activation channel 0: its signal has 3 steps, the rollout has 5");
}

}  // namespace
}  // namespace diffpd::testing
