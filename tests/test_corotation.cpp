// A factorisation kept across steps turned with the scene (engine/linear/corotation): the
// rotation is the one that carries the anchored configuration onto the current one, the turns
// into and out of the anchor's frame are inverse, and what it buys is fewer factorisations
// (simplified Newton) and Jacobians (IDA) on a scene that spins as a whole, with the same
// solutions: the Newton equations are untouched.
#include "support.hpp"

#include "engine/linear/corotation.hpp"
#include "engine/stepping/integrator.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cstdio>
#include <string>
#include <vector>

namespace mpx::test {
namespace {

// z with every spatial vector turned by `rotation`, the points also moved by `shift`.
Eigen::VectorXd turned(const Model& model, const Eigen::VectorXd& z, const Eigen::Matrix3d& rotation,
                       const Eigen::Vector3d& shift) {
  std::vector<Component::SpatialVector> vectors;
  for (const auto& component : model.components()) component->spatialVectors(vectors);
  Eigen::VectorXd out = z;
  for (const auto& vector : vectors) {
    const bool point = vector.kind == Component::SpatialVector::Kind::Point;
    out.segment<3>(vector.first) = rotation * z.segment<3>(vector.first) + (point ? shift : Eigen::Vector3d::Zero());
    out.segment<3>(vector.paired) = rotation * z.segment<3>(vector.paired);
  }
  return out;
}

// The rotation found between a configuration and the same one turned and moved is the turn,
// for rigid bodies (points and directors) and for solid nodes; a vector seen from the turned
// configuration has its spatial vectors turned (the gap multipliers of the governor's joints
// too) and everything else as it was, in each stage; the turns into the anchor's frame and
// back are inverse.
TEST(Corotation, FindsTheRotationBetweenTwoConfigurations) {
  const Eigen::Matrix3d rotation = Eigen::AngleAxisd(0.7, Eigen::Vector3d(1.0, -2.0, 0.5).normalized()).matrix();
  const Eigen::Vector3d shift(0.3, -1.2, 2.0);
  for (const char* file : {"flyball_governor.xml", "lblock_elastic.xml"}) {
    SCOPED_TRACE(file);
    const CompiledScene scene = loadScene(scenePath(file));
    const Model& model = *scene.model;
    const Eigen::VectorXd& z = model.initialState();
    // the governor's three revolute and two spherical joints hold two points together
    std::vector<Component::SpatialVector> vectors;
    for (const auto& component : model.components()) component->spatialVectors(vectors);
    const auto forces = std::count_if(vectors.begin(), vectors.end(), [](const Component::SpatialVector& v) {
      return v.kind == Component::SpatialVector::Kind::Force;
    });
    EXPECT_EQ(forces, std::string(file) == "flyball_governor.xml" ? 5 : 0);
    Corotation corotation(model, 2);
    corotation.anchor(z);
    EXPECT_FALSE(corotation.turned());
    corotation.follow(turned(model, z, rotation, shift));
    ASSERT_TRUE(corotation.turned());
    const int n = model.layout().total();
    const Eigen::VectorXd probe = Eigen::VectorXd::LinSpaced(n, 1.0, 2.0);
    const Eigen::VectorXd stages = probe.replicate(2, 1);
    Eigen::VectorXd seen = stages;
    corotation.fromAnchor(seen);
    const Eigen::VectorXd expected = turned(model, probe, rotation, Eigen::Vector3d::Zero());
    EXPECT_LT((seen.head(n) - expected).cwiseAbs().maxCoeff(), 1e-12);
    EXPECT_LT((seen.tail(n) - expected).cwiseAbs().maxCoeff(), 1e-12);
    corotation.toAnchor(seen);
    EXPECT_LT((seen - stages).cwiseAbs().maxCoeff(), 1e-12);
  }
}

// What the turn rests on: where the scene is invariant under a rotation, the step tangent at the
// turned state is the tangent turned, K(Q z) = Q K(z) Q^T, with Q turning exactly the spatial
// vectors the components list (a gap multiplier left out, or a scalar turned, breaks it). The
// free L-block is invariant under any rotation; the governor, on its bearing about z under
// gravity along z, under rotations about z.
TEST(Corotation, StepTangentTurnsWithTheScene) {
  struct Case {
    const char* file;
    Eigen::Vector3d axis;
  };
  for (const Case& c : {Case{"lblock_elastic.xml", Eigen::Vector3d(1.0, -2.0, 0.5)},
                        Case{"flyball_governor.xml", Eigen::Vector3d::UnitZ()}}) {
    SCOPED_TRACE(c.file);
    const CompiledScene scene = loadScene(scenePath(c.file));
    const Model& model = *scene.model;
    const Eigen::Matrix3d rotation = Eigen::AngleAxisd(0.9, c.axis.normalized()).matrix();
    const Eigen::VectorXd& z = model.initialState();
    const Eigen::VectorXd zTurned = turned(model, z, rotation, Eigen::Vector3d::Zero());
    // Q, column by column: the identity turned
    const int n = model.layout().total();
    Eigen::MatrixXd q(n, n);
    for (int j = 0; j < n; ++j)
      q.col(j) = turned(model, Eigen::VectorXd::Unit(n, j), rotation, Eigen::Vector3d::Zero());
    for (const Scheme scheme : {Scheme::Eem, Scheme::Eem4}) {
      SCOPED_TRACE(schemeName(scheme));
      Integrator integrator(model, scheme, scene.settings.newton);
      const int stages = integrator.stageCount();
      const Eigen::MatrixXd tangent = integrator.evaluate(z, z.replicate(stages, 1), 0.0, scene.settings.dt).tangent();
      const Eigen::MatrixXd turnedTangent =
          integrator.evaluate(zTurned, zTurned.replicate(stages, 1), 0.0, scene.settings.dt).tangent();
      Eigen::MatrixXd qs = Eigen::MatrixXd::Zero(stages * n, stages * n);
      for (int l = 0; l < stages; ++l) qs.block(l * n, l * n, n, n) = q;
      const double mismatch = (turnedTangent - qs * tangent * qs.transpose()).cwiseAbs().maxCoeff();
      std::printf("%s %s: |K(Qz) - Q K(z) Q^T| = %.2e of %.2e\n", c.file, schemeName(scheme).c_str(), mismatch,
                  tangent.cwiseAbs().maxCoeff());
      EXPECT_LT(mismatch, 1e-10 * tangent.cwiseAbs().maxCoeff());
    }
  }
}

constexpr double kSpinTime = 0.2;  // the flyball governor turns by 0.4 pi

// The flyball governor spins at 2 pi rad/s: its factorisation, kept as it was, wears out as the
// augmented-Lagrangian stiffness 1e6 turns with the bodies, and turned with them it serves the
// whole run. The states are the full-Newton ones to the tolerance.
TEST(Corotation, KeepsTheSpinningGovernorsFactorisation) {
  const CompiledScene scene = loadScene(scenePath("flyball_governor.xml"));
  const Model& model = *scene.model;
  const double dt = scene.settings.dt;
  // simplified Newton as scenes/flyball_governor.xml asks for it
  NewtonSettings full = scene.settings.newton, simplified = full;
  full.reuseContraction = 0.0;
  simplified.reuseContraction = 0.5;
  NewtonSettings plain = simplified;
  plain.corotate = false;
  const Eigen::VectorXd magnitude = model.initialState().cwiseAbs() + model.dofScale();
  const int withScale = model.layout().offset(Block::Multiplier);
  for (const Scheme scheme : {Scheme::Eem, Scheme::Eem4}) {
    SCOPED_TRACE(schemeName(scheme));
    const History reference = run(model, scheme, dt, kSpinTime, full);
    const History corotated = run(model, scheme, dt, kSpinTime, simplified);
    const History asItWas = run(model, scheme, dt, kSpinTime, plain);
    for (const History* h : {&reference, &corotated, &asItWas}) ASSERT_FALSE(h->summary.failed) << h->summary.failure;
    const int steps = corotated.summary.steps;
    std::printf("%s: %ld factorisations, %ld iterations turned; %ld, %ld as it was (%d steps)\n",
                schemeName(scheme).c_str(), corotated.summary.factorizations, corotated.summary.newtonIterations,
                asItWas.summary.factorizations, asItWas.summary.newtonIterations, steps);
    EXPECT_LT(corotated.summary.factorizations, 0.05 * steps);
    // (turned: 2 factorisations with eem and with eem4; as it was: 9 and 82 since the velocities
    // have a predictor degree of their own, 25 and 83 before)
    EXPECT_GE(asItWas.summary.factorizations, 3 * corotated.summary.factorizations);
    EXPECT_LT(corotated.summary.newtonIterations, asItWas.summary.newtonIterations);
    const double difference = ((corotated.states.back() - reference.states.back()).head(withScale).array() /
                               magnitude.head(withScale).array())
                                  .abs()
                                  .maxCoeff();
    EXPECT_LT(difference, 1e-8);
    EXPECT_LT(corotated.summary.maxEnergyBalanceError, 1e-9);
  }
}

// IDA's Newton matrix turned with the scene: fewer Jacobians, and a solution as close to a tight
// reference as the one from the matrix as it was, on the spinning governor and the heavy top
// (whose 42 unknowns go through the same condensed solver).
TEST(Corotation, SavesIdaJacobiansOnSpinningScenes) {
  struct Case {
    const char* file;
    double tEnd;
  };
  for (const Case c : {Case{"flyball_governor.xml", kSpinTime}, Case{"heavy_top.xml", 0.5}}) {
    SCOPED_TRACE(c.file);
    const CompiledScene scene = loadScene(scenePath(c.file));
    const Model& model = *scene.model;
    auto runIdaWith = [&](double rtol, bool corotate) {
      MethodParameters parameters;
      parameters.newton.corotate = corotate;
      parameters.dt = c.tEnd / 10;
      parameters.tEnd = c.tEnd;
      parameters.relativeTolerance = parameters.absoluteTolerance = rtol;
      return collect([&](const StepSink& sink) { return runMethod(model, *methodByName("ida"), parameters, sink); });
    };
    const History reference = runIdaWith(1e-11, true), corotated = runIdaWith(1e-7, true),
                  asItWas = runIdaWith(1e-7, false);
    for (const History* h : {&reference, &corotated, &asItWas}) ASSERT_FALSE(h->summary.failed) << h->summary.failure;
    ASSERT_TRUE(corotated.summary.ida && asItWas.summary.ida);
    const int positions = model.layout().size(Block::Position);
    auto error = [&](const History& h) {
      return (h.states.back() - reference.states.back()).head(positions).cwiseAbs().maxCoeff();
    };
    std::printf("%s, IDA rtol 1e-7: %ld Jacobians, error %.2e turned; %ld, %.2e as it was\n", c.file,
                corotated.summary.ida->jacobianEvaluations, error(corotated), asItWas.summary.ida->jacobianEvaluations,
                error(asItWas));
    EXPECT_LT(corotated.summary.ida->jacobianEvaluations, 0.5 * asItWas.summary.ida->jacobianEvaluations);
    EXPECT_LT(error(corotated), 2.0 * error(asItWas) + 1e-6);
  }
}

}  // namespace
}  // namespace mpx::test
