// The paper's rows at the paper's size match the fact sheet (PROBLEMS.md):
// node, DoF and element counts, boundary and contact sets, muscle groups,
// x_init and the random draws; and the rows' error messages.
#include "paper/paper_rows.h"

#include <gtest/gtest.h>

#include <cmath>

#include "control/starfish_control.h"
#include "diffpd/error.h"
#include "paper/activation_variables.h"
#include "paper/row_evaluation.h"

namespace diffpd::problems {
namespace {

void ExpectSizes(const PaperRow& row, int nodes, int dofs, int elements) {
  EXPECT_EQ(row.scene.mesh.num_vertices(), nodes) << row.name;
  EXPECT_EQ(row.scene.mesh.num_dofs(), dofs) << row.name;
  EXPECT_EQ(row.scene.mesh.num_elements(), elements) << row.name;
  EXPECT_NO_THROW(row.scene.Validate()) << row.name;
  EXPECT_EQ(static_cast<int>(row.base.inputs.size()), row.steps) << row.name;
  for (const auto& block : row.variables) EXPECT_NO_THROW(block->CheckFits(row.scene, row.steps)) << row.name;
}

void ExpectNear(const VectorXd& actual, const std::vector<double>& expected, double tolerance) {
  ASSERT_EQ(actual.size(), static_cast<Eigen::Index>(expected.size()));
  for (size_t i = 0; i < expected.size(); ++i) EXPECT_NEAR(actual(i), expected[i], tolerance) << "entry " << i;
}

std::vector<int> MuscleSizes(const Scene& scene) {
  std::vector<int> sizes;
  for (const Muscle& m : scene.muscles) sizes.push_back(static_cast<int>(m.elements.size()));
  return sizes;
}

int ContactCandidates(const Scene& scene) {
  return scene.frictional_contacts.empty() ? 0 : static_cast<int>(scene.frictional_contacts[0].nodes.size());
}

TEST(PaperRowsTest, CantileverHas8019DofsA81NodeClampTwoTipContactNodesAnd32Muscles) {
  const PaperRow row = MakeCantileverRow(RowSize::kPaper);
  ExpectSizes(row, 2673, 8019, 2048);
  EXPECT_EQ(row.scene.dirichlet.dofs.size(), 3u * 81);
  ASSERT_EQ(row.scene.penalty_contacts.size(), 1u);
  EXPECT_EQ(row.scene.penalty_contacts[0].nodes.size(), 2u);
  EXPECT_EQ(row.scene.muscles.size(), 32u);
  EXPECT_EQ(row.scene.muscles[3].elements, std::vector<int>{3 * 64});
  EXPECT_EQ(row.num_variables(), 3 * 8019 + 32);
  EXPECT_EQ(row.steps, 25);
  // The twisted tip: the node at (0.32, 0, 0) turns by pi/2 about (0.04, 0.04).
  const VectorXd x0 = row.Setup(row.initial()).initial.x;
  const int tip = 2673 - 81;  // grid point (32, 0, 0)
  EXPECT_NEAR(x0(3 * tip + 1), 0.08, 1e-12);
  EXPECT_NEAR(x0(3 * tip + 2), 0.0, 1e-12);
}

TEST(PaperRowsTest, RollingSphereHas2469DofsAnd72SingleElementContactNodes) {
  const PaperRow row = MakeRollingSphereRow(RowSize::kPaper);
  ExpectSizes(row, 823, 2469, 552);
  EXPECT_EQ(ContactCandidates(row.scene), 72);
  EXPECT_DOUBLE_EQ(row.scene.mesh.vertices.row(2).minCoeff(), 0.0);
  EXPECT_EQ(row.steps, 100);
}

TEST(PaperRowsTest, PlantHas29763DofsA43NodeClampAndItsDrawnInitialMaterial) {
  const PaperRow row = MakePlantRow(RowSize::kPaper);
  ExpectSizes(row, 9921, 29763, 3863);
  EXPECT_EQ(row.scene.dirichlet.dofs.size(), 3u * 43);
  const MaterialParameters m = row.Setup(row.initial()).material;
  EXPECT_NEAR(m.youngs_modulus, 1.02535e5, 1);
  EXPECT_NEAR(m.poissons_ratio, 0.432369, 1e-6);
  EXPECT_EQ(m.density, 5e3);
  ASSERT_EQ(row.random_draws.size(), 16u);
  EXPECT_TRUE(row.prepare);
}

TEST(PaperRowsTest, BouncingBallIsTheLockMeshScaledWith272ContactNodes) {
  const PaperRow row = MakeBouncingBallRow(RowSize::kPaper);
  ExpectSizes(row, 3044, 9132, 1288);
  EXPECT_EQ(ContactCandidates(row.scene), 272);
  EXPECT_NEAR(row.scene.mesh.vertices.maxCoeff(), 0.2, 1e-12);
  EXPECT_NEAR(row.scene.mesh.vertices.minCoeff(), 0.0, 1e-12);
  const MaterialParameters m = row.Setup(row.initial()).material;
  EXPECT_NEAR(m.youngs_modulus, 9.9005e6, 1e2);
  EXPECT_NEAR(m.poissons_ratio, 0.445522, 1e-6);
  // The normalisation draws are the first 32 after seed 42.
  NumpyRandom rng(42);
  EXPECT_DOUBLE_EQ(row.random_draws[0](0), std::log(1e6) + (std::log(1e7) - std::log(1e6)) * rng.Uniform());
}

TEST(PaperRowsTest, BunnyHas7062DofsAnd251ContactNodesAndItsDrawnPlacement) {
  const PaperRow row = MakeBunnyRow(RowSize::kPaper);
  ExpectSizes(row, 2354, 7062, 1601);
  EXPECT_EQ(ContactCandidates(row.scene), 251);
  ExpectNear(row.initial(),
             {-0.262763, 0.943974, 0.485887, 0.001973, -0.006880, 0.193120, -1.325749, 1.098528, -3.797770}, 1e-6);
  // The placed bunny's mean node is c and its velocity v_c.
  const solvers::RolloutSetup s = row.Setup(row.initial());
  const Eigen::Map<const Eigen::Matrix3Xd> x(s.initial.x.data(), 3, 2354);
  EXPECT_NEAR((Vec3(x.rowwise().mean()) - Vec3(0.001973, -0.006880, 0.193120)).norm(), 0, 1e-6);
  EXPECT_NEAR((Vec3(s.initial.v.segment<3>(0)) - Vec3(-1.325749, 1.098528, -3.797770)).norm(), 0, 1e-6);
}

TEST(PaperRowsTest, RoutingTendonHas16GroupsOf32ElementsAndItsDrawnActivations) {
  const PaperRow row = MakeRoutingTendonRow(RowSize::kPaper);
  ExpectSizes(row, 825, 2475, 512);
  EXPECT_EQ(row.scene.dirichlet.dofs.size(), 3u * 25);
  EXPECT_EQ(MuscleSizes(row.scene), std::vector<int>(16, 32));
  ExpectNear(row.initial(),
             {0.749080, 1.901429, 1.463988, 1.197317, 0.312037, 0.311989, 0.116167, 1.732352, 1.202230, 1.416145,
              0.041169, 1.939820, 1.664885, 0.424678, 0.363650, 0.366809},
             1e-6);
  EXPECT_NEAR((Vec3(row.scene.mesh.vertices.col(824)) - Vec3(0.1, 0.1, 0.8)).norm(), 0, 1e-12);
}

TEST(PaperRowsTest, TorusHas8GroupsOfTheSheetsSizesAnd160Variables) {
  const PaperRow row = MakeTorusRow(RowSize::kPaper);
  ExpectSizes(row, 1068, 3204, 568);
  EXPECT_EQ(ContactCandidates(row.scene), 136);
  EXPECT_EQ(MuscleSizes(row.scene), (std::vector<int>{76, 66, 76, 66, 66, 76, 66, 76}));
  EXPECT_EQ(row.num_variables(), 160);
  EXPECT_EQ(row.steps, 400);
  EXPECT_EQ(row.initial_guess, InitialGuess::kBestRandomDraw);
  // The 16 draws follow 160 discarded ones.
  NumpyRandom rng(42);
  for (int i = 0; i < 160; ++i) rng.Uniform();
  EXPECT_EQ(row.random_draws[0](0), 2.0 * rng.Uniform());
}

TEST(PaperRowsTest, QuadrupedHas3180DofsFourLegsOf36Plus18ElementsAndAProjectedStart) {
  const PaperRow row = MakeQuadrupedRow(RowSize::kPaper);
  ExpectSizes(row, 1060, 3180, 648);
  EXPECT_EQ(ContactCandidates(row.scene), 48);
  // Muscles 4 front + 2 forward + left: the forward ("F") ones have 36.
  EXPECT_EQ(MuscleSizes(row.scene), (std::vector<int>{18, 18, 36, 36, 18, 18, 36, 36}));
  ExpectNear(row.initial_unprojected(), {0.006873, 0.009754, 0.009367}, 1e-6);
  ExpectNear(row.initial(), {0.5, 0.5, 2 * M_PI / 100}, 1e-15);
}

TEST(PaperRowsTest, CowHasTheSheetsLegGroupsAnd32ContactNodes) {
  const PaperRow row = MakeCowRow(RowSize::kPaper);
  ExpectSizes(row, 816, 2448, 475);
  EXPECT_EQ(ContactCandidates(row.scene), 32);
  // RRB, RLB, RRF, RLF, FRB, FLB, FRF, FLF.
  EXPECT_EQ(MuscleSizes(row.scene), (std::vector<int>{7, 7, 7, 8, 8, 8, 8, 8}));
  ExpectNear(row.initial(), {0.543083, 0.808107, 0.386200}, 1e-6);
  EXPECT_EQ(row.steps, 575);
}

// Rows 10 and 11 are the control problems' swimmers, their network's
// weights the variables, at the control problems' sizes and steps.
TEST(PaperRowsTest, StarfishAndSharkRowsAreTheControlProblemsSwimmersWithTheirWeightsAsVariables) {
  const PaperRow starfish = MakeStarfishRow(RowSize::kPaper);
  ExpectSizes(starfish, 387, 1161, 168);
  EXPECT_EQ(starfish.steps, 200);
  EXPECT_EQ(starfish.scene.muscles.size(), 160u);
  // 243-64-64-4: (243 + 1) 64 + (64 + 1) 64 + (64 + 1) 4.
  EXPECT_EQ(starfish.num_variables(), 244 * 64 + 65 * 64 + 65 * 4);
  EXPECT_EQ(starfish.table_index, 10);
  EXPECT_FALSE(starfish.budget.optimised);
  const PaperRow shark = MakeSharkRow(RowSize::kPaper);
  ExpectSizes(shark, 1324, 3972, 832);
  EXPECT_EQ(shark.steps, 200);
  EXPECT_EQ(shark.scene.muscles.size(), 8u * 28);
  EXPECT_EQ(shark.num_variables(), 250 * 64 + 65 * 64 + 65 * 2);
  EXPECT_EQ(shark.table_index, 11);
  for (const PaperRow* row : {&starfish, &shark}) {
    EXPECT_EQ(row->solver.rel_tolerance, 1e-3) << row->name;
    EXPECT_EQ(row->solver.abs_tolerance, 1e-4) << row->name;
    EXPECT_TRUE(row->Setup(row->initial()).controller) << row->name;
  }
}

// A closed-loop row evaluates the rollout its controller drives: the loss and
// gradient are those of the swimmer's own rollout function at the same
// weights (an open-loop rollout of the row's empty inputs would not move).
// The closed-loop gradient itself is checked against central differences in
// closed_loop_gradient_test; the starfish's one-sided faces (a face's force
// jumps where it turns away from the flow) make differences of its whole
// rollout depend on the step (1e-4 to 1e-6 of the weights: 0.48, 0.11, 0.547
// against the adjoint's 0.547), so no row gradient test differences it.
TEST(PaperRowsTest, AStarfishRowEvaluationIsTheSwimmersClosedLoopRollout) {
  const PaperRow row = MakeStarfishRow(RowSize::kSmall);
  const SolverOptions options = row.Options(Method::kPdLbfgs, 1);
  Simulator sim(row.scene, options);
  const RowEvaluation e = EvaluateRow(row, &sim, row.initial(), true);
  const Swimmer swimmer = StarfishControl().MakeSwimmer(true);
  Swimmer same_masses = swimmer;
  same_masses.scene.mass_lumping = row.scene.mass_lumping;
  const auto f = MakeSwimmerFunction(same_masses, options, 42);
  ASSERT_EQ(f->num_parameters(), row.num_variables());
  EXPECT_EQ(f->initial_parameters(), row.initial());
  VectorXd gradient;
  double value = 0;
  ASSERT_TRUE(f->Gradient(row.initial(), VectorXd::Ones(1), &gradient, &value)) << f->statistics().last_error;
  EXPECT_NEAR(e.loss, value, 1e-12 * std::abs(value));
  EXPECT_GT(std::abs(e.loss), 1e-3);
  EXPECT_LE((e.gradient - gradient).norm(), 1e-10 * gradient.norm());
}

TEST(PaperRowsTest, UnknownRowNameListsTheValidOnes) {
  try {
    MakePaperRow("water-snake", RowSize::kSmall);
    FAIL() << "expected InvalidInputError";
  } catch (const InvalidInputError& e) {
    EXPECT_STREQ(e.what(),
                 "unknown table row 'water-snake': valid rows are cantilever, rolling-sphere, plant, bouncing-ball, "
                 "bunny, routing-tendon, torus, quadruped, cow, starfish, shark");
  }
}

TEST(PaperRowsTest, EvaluatingBeforeThePreparatorySimulationsIsRefused) {
  const PaperRow row = MakePlantRow(RowSize::kSmall);
  Simulator sim(row.scene, row.Options(Method::kPdLbfgs, 1));
  try {
    EvaluateRow(row, &sim, row.initial(), false);
    FAIL() << "expected InvalidInputError";
  } catch (const InvalidInputError& e) {
    EXPECT_STREQ(e.what(), "plant: the row needs its preparatory simulations first (PaperRow::Prepare)");
  }
}

TEST(PaperRowsTest, VariablesOfTheWrongSizeAreRefused) {
  const PaperRow row = MakeCowRow(RowSize::kSmall);
  try {
    row.Setup(VectorXd::Zero(2));
    FAIL() << "expected InvalidInputError";
  } catch (const InvalidInputError& e) {
    EXPECT_STREQ(e.what(), "cow: the variables has 2 entries, expected 3 (one per variable)");
  }
}

int StepTestNotes(const PaperRow& row, const std::string& start) {
  int n = 0;
  for (const std::string& note : row.notes) n += note.rfind(start, 0) == 0;
  return n;
}

// Every method of a row runs the row's step test, and the row's notes state
// which test it is, once: the original's, or this library's where the
// original's is off the row's measured front (bunny, bouncing ball).
TEST(PaperRowsTest, EachRowsMethodsRunItsStepTestAndItsNotesSayWhich) {
  for (const std::string& name : PaperRowNames()) {
    const PaperRow row = MakePaperRow(name, RowSize::kSmall);
    const bool start_residual = name == "bunny" || name == "bouncing-ball";
    const ToleranceReference expected =
        start_residual ? ToleranceReference::kStartResidual : ToleranceReference::kInertia;
    for (Method m : {Method::kPdLbfgs, Method::kNewtonCholesky, Method::kNewtonPcg})
      EXPECT_EQ(row.Options(m, 1).tolerance_reference, expected) << name;
    EXPECT_EQ(StepTestNotes(row, "step tolerance: "), 1) << name;
    EXPECT_EQ(StepTestNotes(row, "step tolerance: this library's test for every method"), start_residual ? 1 : 0)
        << name;
  }
}

}  // namespace
}  // namespace diffpd::problems
