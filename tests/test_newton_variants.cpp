// Newton variants (engine/stepping/integrator.cpp, newton.cpp): the predictor (start from the extrapolation of
// the last states), simplified Newton (a factorisation kept while the increments contract)
// and full Newton that keeps its factorisation close to the solution change how the step's
// equations are solved, never which equations: each run reaches the full-Newton solution to
// the Newton tolerance and keeps the energy balance.
#include "support.hpp"

#include "engine/stepping/adaptive_simulation.hpp"
#include "engine/stepping/integrator.hpp"
#include "engine/stepping/loop_state.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cstdio>
#include <filesystem>

namespace mpx::test {
namespace {

struct Variant {
  const char* name;
  bool predictor;
  double reuseContraction;
  double reuseBelowIncrement;
};

constexpr Variant kVariants[] = {{"predictor", true, 0.0, 0.0},
                                 {"simplified", false, 0.25, 0.0},
                                 {"both", true, 0.25, 0.0},
                                 {"kept near the solution", false, 0.0, 1e-4},
                                 {"predictor, kept near the solution", true, 0.0, 1e-4}};

class NewtonVariants : public ::testing::TestWithParam<const char*> {};

constexpr int kSteps = 20;

// Simplified Newton evaluates the residual alone at the iterates it does not factorise at; the
// second- and fourth-order EEM steps both go through that path.
TEST_P(NewtonVariants, ReachTheFullNewtonSolutionToTheTolerance) {
  const CompiledScene scene = loadScene(scenePath(GetParam()));
  const Model& model = *scene.model;
  const double dt = scene.settings.dt, tEnd = kSteps * dt;
  NewtonSettings full = scene.settings.newton;
  full.predictor = false;
  full.reuseContraction = 0.0;
  full.reuseBelowIncrement = 0.0;
  const Eigen::VectorXd scale = model.dofScale();
  const int withScale = model.layout().offset(Block::Multiplier);
  for (const Scheme scheme : {Scheme::Eem, Scheme::Eem4}) {
    SCOPED_TRACE(schemeName(scheme));
    const History reference = run(model, scheme, dt, tEnd, full);
    ASSERT_FALSE(reference.summary.failed) << reference.summary.failure;
    const Eigen::VectorXd magnitude = reference.states.back().cwiseAbs() + scale;
    for (const Variant& v : kVariants) {
      NewtonSettings settings = full;
      settings.predictor = v.predictor;
      settings.reuseContraction = v.reuseContraction;
      settings.reuseBelowIncrement = v.reuseBelowIncrement;
      const History h = run(model, scheme, dt, tEnd, settings);
      ASSERT_FALSE(h.summary.failed) << v.name << ": " << h.summary.failure;
      // kSteps steps, each solved to an increment of 1e-10 relative: the states agree to 1e-8
      const double difference =
          ((h.states.back() - reference.states.back()).head(withScale).array() / magnitude.head(withScale).array())
              .abs()
              .maxCoeff();
      EXPECT_LT(difference, 1e-8) << v.name;
      EXPECT_LT(h.summary.maxEnergyBalanceError, 1e-9) << v.name;
      // what each variant is for: fewer factorisations than iterations when they are kept;
      // full Newton factorises at least once a step, and its last corrections come from the
      // factorisation in hand
      EXPECT_LT(h.summary.factorizations, h.summary.newtonIterations) << v.name;
      if (v.reuseContraction == 0.0) {
        EXPECT_GE(h.summary.factorizations, kSteps) << v.name;
      }
      // keeping the factorisation near the solution costs at most one more iteration in ten steps
      if (v.reuseBelowIncrement > 0.0 && v.reuseContraction == 0.0 && !v.predictor) {
        EXPECT_LE(h.summary.newtonIterations, reference.summary.newtonIterations + 2) << v.name;
      }
    }
  }
}

// Every scene in scenes/ that keeps its factorisation (the finite-element scenes and the flyball
// governor ask for simplified Newton) reaches over its first kSteps steps the states full Newton
// reaches, to the same 1e-8 as the variants above, and keeps every step's energy balance within
// 1e-9 of its largest energy: the scenes' own settings change the cost of a step, not its result.
// (The flexible pendulum keeps full Newton: with its factorisation kept, a step's balance reached
// only 2.8e-9 over these steps.)
TEST(SimplifiedNewton, EveryShippedSceneThatKeepsItsFactorisationReachesFullNewton) {
  int scenes = 0;
  for (const auto& entry : std::filesystem::directory_iterator(METRIPLEX_SCENES_DIR)) {
    if (entry.path().extension() != ".xml") continue;
    const CompiledScene scene = loadScene(entry.path().string());
    if (scene.settings.newton.reuseContraction <= 0.0) continue;
    SCOPED_TRACE(entry.path().filename().string());
    ++scenes;
    const Model& model = *scene.model;
    NewtonSettings full = scene.settings.newton;
    full.reuseContraction = 0.0;
    full.symmetricFactorisation = false;
    const double dt = scene.settings.dt, tEnd = kSteps * dt;
    const History reference = run(model, Scheme::Eem, dt, tEnd, full);
    const History kept = run(model, Scheme::Eem, dt, tEnd, scene.settings.newton);
    ASSERT_FALSE(reference.summary.failed) << reference.summary.failure;
    ASSERT_FALSE(kept.summary.failed) << kept.summary.failure;
    const int withScale = model.layout().offset(Block::Multiplier);
    const Eigen::VectorXd magnitude = reference.states.back().cwiseAbs() + model.dofScale();
    const double difference =
        ((kept.states.back() - reference.states.back()).head(withScale).array() / magnitude.head(withScale).array())
            .abs()
            .maxCoeff();
    EXPECT_LT(difference, 1e-8);
    EXPECT_LT(kept.summary.maxEnergyBalanceError, 1e-9);
    EXPECT_LT(kept.summary.factorizations, reference.summary.factorizations);
  }
  EXPECT_EQ(scenes, 13);  // twelve finite-element scenes and the flyball governor
}

// Under adaptive steps simplified Newton keeps a factorisation across step-size changes of up
// to a fifth: the steps still solve the same equations, so the run takes the same steps to the
// same states as with full Newton, and every accepted step keeps the EEM balances.
TEST(SimplifiedNewton, AdaptiveStepsReachTheFullNewtonRun) {
  const CompiledScene scene = loadScene(scenePath("lblock_viscoelastic.xml"));
  const Model& model = *scene.model;
  NewtonSettings full = scene.settings.newton, simplified = full;
  full.reuseContraction = 0.0;
  simplified.reuseContraction = 0.5;
  constexpr double kEndTime = 3.0, kRtol = 1e-5;
  const Eigen::VectorXd scale = model.dofScale();
  const int withScale = model.layout().offset(Block::Multiplier);
  for (const Scheme scheme : {Scheme::Eem, Scheme::Eem4}) {
    SCOPED_TRACE(schemeName(scheme));
    auto runWith = [&](const NewtonSettings& newton) {
      return collect([&](const StepSink& sink) {
        return simulateAdaptive(model, {scheme, 0.05, kEndTime, newton, {}}, {kRtol, kRtol, 0.0}, sink);
      });
    };
    const History reference = runWith(full), h = runWith(simplified);
    ASSERT_FALSE(reference.summary.failed) << reference.summary.failure;
    ASSERT_FALSE(h.summary.failed) << h.summary.failure;
    // what simplified Newton is for, on steps whose sizes change
    EXPECT_LT(h.summary.factorizations, 0.5 * h.summary.newtonIterations);
    const auto [shortest, longest] = std::minmax_element(h.dt.begin() + 1, h.dt.end());
    EXPECT_GT(*longest, 1.5 * *shortest);
    // the step sequences agree, and the states to well below the error tolerance
    ASSERT_EQ(h.dt.size(), reference.dt.size());
    for (std::size_t k = 1; k < h.dt.size(); ++k) ASSERT_NEAR(h.dt[k], reference.dt[k], 1e-6 * reference.dt[k]) << k;
    const Eigen::VectorXd magnitude = reference.states.back().cwiseAbs() + scale;
    const double difference =
        ((h.states.back() - reference.states.back()).head(withScale).array() / magnitude.head(withScale).array())
            .abs()
            .maxCoeff();
    const double balance = maxBalanceDrift(h) / largestEnergy(h);
    std::printf(
        "%s: %zu steps, %ld factorisations for %ld iterations (full: %ld); states differ by %.2e; balance %.2e\n",
        schemeName(scheme).c_str(), h.dt.size() - 1, h.summary.factorizations, h.summary.newtonIterations,
        reference.summary.factorizations, difference, balance);
    EXPECT_LT(difference, 1e-7);
    // the block starts at rest: the balance is judged against the work the load does
    EXPECT_LT(balance, 1e-11);
    EXPECT_EQ(firstEntropyDecrease(h), -1);
  }
}

// A kept factorisation serves the next step when its size changes by at most a fifth; a larger
// change, or a restart after checkpoint(), factorises afresh. Steps from the same state with the
// same step size reach the same end state either way (to the Newton tolerance).
TEST(SimplifiedNewton, KeepsItsFactorisationAcrossSmallStepChangesOnly) {
  const CompiledScene scene = loadScene(scenePath("two_thermo_springs.xml"));
  const Model& model = *scene.model;
  NewtonSettings settings = scene.settings.newton;
  settings.reuseContraction = 0.5;
  settings.predictor = false;
  const double dt = 0.01;
  const Eigen::VectorXd& z0 = model.initialState();
  Eigen::VectorXd z1(z0.size()), z2(z0.size()), fresh(z0.size());
  struct Case {
    double stepChange;
    bool restart;
    bool refactorises;
  };
  for (const Case c :
       {Case{1.15, false, false}, Case{0.85, false, false}, Case{1.3, false, true}, Case{1.15, true, true}}) {
    SCOPED_TRACE(testing::Message() << "step change " << c.stepChange << (c.restart ? ", after a checkpoint" : ""));
    Integrator integrator(model, Scheme::Eem, settings);
    const StepOutcome first = integrator.advance(z0, 0.0, dt, z1);
    ASSERT_TRUE(first.converged) << first.failure;
    ASSERT_GE(first.factorizations, 1);
    if (c.restart) {
      LoopState saved;
      integrator.checkpoint(saved);
    }
    const StepOutcome second = integrator.advance(z1, dt, c.stepChange * dt, z2);
    ASSERT_TRUE(second.converged) << second.failure;
    EXPECT_EQ(second.factorizations > 0, c.refactorises) << second.factorizations << " factorisations";
    // the kept factorisation changes how the step is solved, not its end state
    Integrator fullNewton(model, Scheme::Eem, scene.settings.newton);
    ASSERT_TRUE(fullNewton.advance(z1, dt, c.stepChange * dt, fresh).converged);
    EXPECT_LT(((z2 - fresh).array() / (fresh.array().abs() + model.dofScale().array())).abs().maxCoeff(), 1e-9);
  }
}

// The predictor saves iterations where the trajectory is smooth: the two thermo-springs in
// temperature form take 4.05 iterations per step from the old state over t in [0, 20] and
// 3.25 from the extrapolation (4.02 and 2.29 over t in [0, 2000]).
TEST(NewtonPredictor, SavesIterationsOnASmoothTrajectory) {
  const CompiledScene scene = loadScene(scenePath("two_thermo_springs.xml"), ThermalVariable::Temperature);
  NewtonSettings off = scene.settings.newton, on = off;
  off.predictor = false;
  on.predictor = true;
  const History without = run(*scene.model, Scheme::Eem, 0.2, 20.0, off);
  const History with = run(*scene.model, Scheme::Eem, 0.2, 20.0, on);
  // (a run that stopped early would count fewer iterations)
  ASSERT_FALSE(without.summary.failed) << without.summary.failure;
  ASSERT_FALSE(with.summary.failed) << with.summary.failure;
  ASSERT_EQ(with.summary.steps, without.summary.steps);
  EXPECT_LT(with.summary.newtonIterations, 0.9 * without.summary.newtonIterations)
      << with.summary.newtonIterations << " against " << without.summary.newtonIterations;
}

// The predictor is the polynomial through the last (up to four) states whose degree came
// closest at the last step, and eem4 takes its stages from it: a mass falling under gravity
// moves on a parabola, which EEM, midpoint, trapezoidal and eem4 all reproduce exactly at any
// step. The line through the first two states misses by g dt^2 (two Newton iterations per
// step); once three states have shown the parabola to be closer (from the fourth step on) the
// predicted state is the solution and each step takes one iteration, to the same states.
TEST(NewtonPredictor, PredictsAFreeFallExactly) {
  const CompiledScene scene = loadSceneText(R"(<metriplex name="fall"><simulation dt="0.1" t_end="2"/>
      <gravity g="0 0 -9.81"/><mass name="m" mass="2" position="0 0 0" velocity="1 0 3"/></metriplex>)",
                                            "fall.xml");
  NewtonSettings off = scene.settings.newton, on = off;
  off.predictor = false;
  on.predictor = true;
  for (const Scheme scheme : {Scheme::Eem, Scheme::Midpoint, Scheme::Trapezoidal, Scheme::Eem4}) {
    const History without = run(*scene.model, scheme, 0.1, 2.0, off);
    const History with = run(*scene.model, scheme, 0.1, 2.0, on);
    EXPECT_EQ(with.summary.newtonIterations, 2 * 3 + 17) << schemeName(scheme);
    EXPECT_EQ(without.summary.newtonIterations, 2 * 20) << schemeName(scheme);
    EXPECT_LT((with.states.back() - without.states.back()).cwiseAbs().maxCoeff(), 1e-12) << schemeName(scheme);
  }
}

// A mechanism's velocities take their own predictor degree. The one-stage schemes keep the
// positions on the constraints at the step ends, and the positions' increments are the
// velocities' step means, so the velocities across turning constraints carry a component that
// flips its sign from step to step: a higher degree mispredicts it by more, while the positions
// stay smooth and gain from one. The free-floating chain (EEM at its dt 0.01, t in [0, 5]) took
// 5.12 iterations per step with one degree for the whole state and takes 3.51 with two; the run
// reaches the states of the run without the predictor to the Newton tolerance.
TEST(NewtonPredictor, VelocitiesOfAConstrainedMechanismTakeTheirOwnDegree) {
  const CompiledScene scene = loadScene(scenePath("free_floating_chain.xml"));
  NewtonSettings off = scene.settings.newton, on = off;
  off.predictor = false;
  on.predictor = true;
  const double dt = scene.settings.dt, tEnd = scene.settings.tEnd;
  const History without = run(*scene.model, Scheme::Eem, dt, tEnd, off);
  const History with = run(*scene.model, Scheme::Eem, dt, tEnd, on);
  ASSERT_FALSE(with.summary.failed) << with.summary.failure;
  EXPECT_LT(with.summary.newtonIterations, 4.0 * with.summary.steps)
      << "without the predictor: " << without.summary.newtonIterations;
  const Eigen::VectorXd magnitude = without.states.back().cwiseAbs() + scene.model->dofScale();
  const int positionsAndVelocities = scene.model->layout().offset(Block::Thermal);
  EXPECT_LT(((with.states.back() - without.states.back()).cwiseQuotient(magnitude))
                .head(positionsAndVelocities)
                .cwiseAbs()
                .maxCoeff(),
            1e-8);
}

// eem4's stages start from the polynomial through the past states at the stage times, plus the
// last step's stage error (Gauss stages are an order lower than the ends the polynomial runs
// through) where the steps resolve the motion. The two thermo-springs at dt 0.2 over t in
// [0, 20]: 309 iterations (2.33 per step over [0, 200]), where the stages on the line through
// the last two states took 337 and the polynomial alone 317; the thermo-visco-elastic element
// at its dt 0.1: 2.08 per step, where the polynomial alone takes 2.9 (its second increment is
// then just above the tolerance, and a third iteration follows).
TEST(NewtonPredictor, Eem4StagesFromThePastStatesSaveIterations) {
  const CompiledScene springs = loadScene(scenePath("two_thermo_springs.xml"));
  NewtonSettings off = springs.settings.newton, on = off;
  off.predictor = false;
  on.predictor = true;
  const History without = run(*springs.model, Scheme::Eem4, 0.2, 20.0, off);
  const History with = run(*springs.model, Scheme::Eem4, 0.2, 20.0, on);
  ASSERT_FALSE(with.summary.failed) << with.summary.failure;
  EXPECT_LT(with.summary.newtonIterations, 315) << "without the predictor: " << without.summary.newtonIterations;
  EXPECT_LT(with.summary.newtonIterations, without.summary.newtonIterations);
  const CompiledScene element = loadScene(scenePath("thermo_visco_elastic.xml"));
  const History visco = run(*element.model, Scheme::Eem4, 0.1, 20.0, element.settings.newton);
  ASSERT_FALSE(visco.summary.failed) << visco.summary.failure;
  EXPECT_LT(visco.summary.newtonIterations, 2.2 * 200);
}

// Where the arguments of eem4's stage gradients barely move, the step residual carries up to
// 1e-11 relative round-off (engine/core/stage_gradient.hpp) and Newton's corrections wander
// around the increment tolerance: the two thermo-springs, whose oscillation has nearly died out
// between t = 8000 and 16000, took up to 5 iterations and 4 factorisations per step there
// (2.98 and 1.97 per step over [0, 20000], 0.0006 cut-backs per step from Newton running out of
// iterations). A correction from the factorisation made at the iterate before, following one
// within 1e-8, is now the last up to ten times the tolerance: 2.0 and 1.0 per step, with every
// step's energy balance as exact as before (largest 6.8e-15 of the energy either way).
TEST(NewtonRoundOff, Eem4TakesTwoIterationsWhereItsResidualIsAtRoundOff) {
  const CompiledScene scene = loadScene(scenePath("two_thermo_springs.xml"));
  const History h = run(*scene.model, Scheme::Eem4, 0.2, 13000.0, scene.settings.newton);
  ASSERT_FALSE(h.summary.failed) << h.summary.failure;
  const double steps = h.summary.steps;
  std::printf("eem4, t in [0, 13000]: %.3f iterations, %.3f factorisations per step\n",
              h.summary.newtonIterations / steps, h.summary.factorizations / steps);
  EXPECT_LT(h.summary.newtonIterations / steps, 2.1);
  EXPECT_LT(h.summary.factorizations / steps, 1.1);
  double worst = 0.0;
  for (std::size_t n = 1; n < h.energy.size(); ++n) {
    const double balance = (h.energy[n] + h.dissipated[n] - h.externalWork[n] - h.boundaryHeat[n]) -
                           (h.energy[n - 1] + h.dissipated[n - 1] - h.externalWork[n - 1] - h.boundaryHeat[n - 1]);
    worst = std::max(worst, std::abs(balance) / std::abs(h.energy[n]));
  }
  std::printf("largest energy balance error of a step: %.3e of the energy\n", worst);
  EXPECT_LT(worst, 1e-14);
}

// On a system large enough for the sparse Cholesky path (the L-block at mesh level 3: 4116
// condensed unknowns), simplified Newton with the symmetric part factorised by CHOLMOD solves
// with an approximate matrix, so it needs more iterations, but it judges its iterates on the
// true residual: it reaches the full-Newton states and keeps the energy balance.
TEST(SimplifiedNewton, SymmetricFactorisationReachesTheFullNewtonSolution) {
  std::string text = readFile(std::string(METRIPLEX_SCENES_DIR) + "/lblock_elastic.xml");
  text.replace(text.find("level=\"1\""), 9, "level=\"3\"");
  const CompiledScene scene = loadSceneText(text, "lblock_level3.xml");
  const Model& model = *scene.model;
  const double dt = scene.settings.dt, tEnd = 3 * dt;
  NewtonSettings full = scene.settings.newton;
  full.reuseContraction = 0.0;
  const History reference = run(model, Scheme::Eem, dt, tEnd, full);
  ASSERT_FALSE(reference.summary.failed) << reference.summary.failure;
  NewtonSettings symmetric = scene.settings.newton;
  symmetric.reuseContraction = 0.5;
  symmetric.symmetricFactorisation = true;
  const History h = run(model, Scheme::Eem, dt, tEnd, symmetric);
  ASSERT_FALSE(h.summary.failed) << h.summary.failure;
  EXPECT_NE(h.summary.linearSystem.find("CHOLMOD"), std::string::npos) << h.summary.linearSystem;
  const Eigen::VectorXd magnitude = reference.states.back().cwiseAbs() + model.dofScale();
  EXPECT_LT(((h.states.back() - reference.states.back()).array() / magnitude.array()).abs().maxCoeff(), 1e-8);
  EXPECT_LT(h.summary.maxEnergyBalanceError, 1e-9);
  EXPECT_LT(h.summary.factorizations, h.summary.newtonIterations);
}

INSTANTIATE_TEST_SUITE_P(Scenes, NewtonVariants,
                         ::testing::Values("two_thermo_springs.xml", "thermo_visco_elastic.xml",
                                           "damped_double_pendulum.xml", "lblock_viscoelastic.xml"),
                         [](const auto& info) {
                           std::string name = info.param;
                           return name.substr(0, name.find('.'));
                         });

}  // namespace
}  // namespace mpx::test
