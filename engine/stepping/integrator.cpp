#include "engine/stepping/integrator.hpp"

#include <cmath>
#include <cstdio>

namespace mpx {

namespace {
// Backtracking gives up (and the step is cut back) below this fraction of a Newton step.
constexpr double kSmallestLineSearchStep = 1.0 / 1024;
}  // namespace

Integrator::Integrator(const Model& model, Scheme scheme, NewtonSettings settings)
    : model_(model),
      scheme_(scheme),
      settings_(settings),
      assembler_(model),
      solver_(model.layout(), assembler_.tangent()),
      workspace_(model.makeWorkspace()),
      zMid_(model.layout().total()),
      zDot_(model.layout().total()),
      increment_(model.layout().total()),
      trial_(model.layout().total()),
      unknownsWithScale_(model.layout().offset(Block::Multiplier)),
      halfState_(settings.maxCutbacks + 1, Eigen::VectorXd(model.layout().total())) {}

Assembler& Integrator::evaluate(const Eigen::VectorXd& zOld, const Eigen::VectorXd& zNew, double t, double dt) {
  assembler_.clear();
  if (scheme_ == Scheme::Eem) {
    assembler_.addStep(model_, workspace_, {zOld.data(), zNew.data(), t, dt});
  } else {
    addRateForm(zOld, zNew, t, dt);
  }
  assembler_.imposeStepMotions(model_, zOld.data(), zNew.data(), t, dt);
  return assembler_;
}

void Integrator::addRateForm(const Eigen::VectorXd& zOld, const Eigen::VectorXd& zNew, double t, double dt) {
  zDot_ = (zNew - zOld) / dt;
  // midpoint: F(t + dt/2, (z + z')/2, (z' - z)/dt)
  if (scheme_ == Scheme::Midpoint) {
    zMid_ = 0.5 * (zOld + zNew);
    assembler_.addRate(model_, workspace_, {zMid_.data(), zDot_.data(), t + 0.5 * dt, 0.5, 1.0 / dt}, 1.0);
    return;
  }
  // trapezoidal: mean of F at both end points with the same (z' - z)/dt
  assembler_.addRate(model_, workspace_, {zOld.data(), zDot_.data(), t, 0.0, 1.0 / dt}, 0.5);
  assembler_.addRate(model_, workspace_, {zNew.data(), zDot_.data(), t + dt, 1.0, 1.0 / dt}, 0.5);
}

bool Integrator::solveStep(const Eigen::VectorXd& zOld, double t, double dt, Eigen::VectorXd& zNew,
                           StepOutcome& outcome) {
  const Eigen::VectorXd& scale = model_.dofScale();
  auto fail = [&](const char* what, int iteration, double incrementNorm, double residualNorm) {
    std::snprintf(outcome.failure, sizeof outcome.failure, "%s (Newton iteration %d, increment %.3g, residual %.3g)",
                  what, iteration, incrementNorm, residualNorm);
    return false;
  };
  // the residual norm relative to row scales taken at the current iterate
  auto rescaledNorm = [&](Assembler& system) {
    stateScale_ = zNew.cwiseAbs() + scale;
    system.updateRowScale(stateScale_);
    return system.relativeResidualNorm();
  };

  zNew = zOld;
  Assembler& system = evaluate(zOld, zNew, t, dt);
  double residualNorm = rescaledNorm(system);
  double incrementNorm = INFINITY;
  if (!std::isfinite(residualNorm)) return fail("non-finite residual at the start of the step", 0, 0.0, residualNorm);
  for (int iteration = 0;; ++iteration) {
    if (iteration > 0 && incrementNorm <= settings_.incrementTolerance && residualNorm <= settings_.residualTolerance) {
      outcome.energy += system.flows() * dt;
      return true;
    }
    if (iteration == settings_.maxIterations)
      return fail("Newton did not converge", iteration, incrementNorm, residualNorm);
    // backtrack along the Newton direction until the residual is finite and decreases (a
    // full step near the solution, where the residual is already at round-off level); if no
    // step decreases it, the reused pivots may be to blame: pivot afresh once
    double step = 1.0;
    for (bool repivot = false;;) {
      if (!solver_.factorize(system.tangent(), repivot))
        return fail("singular tangent", iteration, incrementNorm, residualNorm);
      solver_.solve(system.residual(), increment_);
      step = lineSearch(zOld, t, dt, zNew, residualNorm);
      if (step > 0.0) break;
      if (repivot)
        return fail("no decrease of the residual along the Newton direction", iteration, incrementNorm, residualNorm);
      repivot = true;
      evaluate(zOld, zNew, t, dt);  // restore the tangent at zNew
    }
    zNew.swap(trial_);
    ++outcome.iterations;
    // multipliers have no natural scale; their rows' residual (the constraints) judges them
    incrementNorm = step * (increment_.head(unknownsWithScale_).array().abs() /
                            (zNew.head(unknownsWithScale_).array().abs() + scale.head(unknownsWithScale_).array()))
                               .maxCoeff();
    residualNorm = rescaledNorm(system);
  }
}

double Integrator::lineSearch(const Eigen::VectorXd& zOld, double t, double dt, const Eigen::VectorXd& zNew,
                              double residualNorm) {
  for (double step = 1.0; step >= kSmallestLineSearchStep; step *= 0.5) {
    trial_ = zNew + step * increment_;
    evaluate(zOld, trial_, t, dt);
    const double trialNorm = assembler_.relativeResidualNorm();
    if (trialNorm <= (1.0 - 1e-4 * step) * residualNorm ||
        (std::isfinite(trialNorm) && residualNorm <= settings_.residualTolerance))
      return step;
  }
  return 0.0;
}

bool Integrator::advanceLevel(const Eigen::VectorXd& z, double t, double dt, int level, Eigen::VectorXd& zNew,
                              StepOutcome& outcome) {
  if (solveStep(z, t, dt, zNew, outcome)) return true;
  if (level == settings_.maxCutbacks) return false;
  // cut back: two half steps through an intermediate state of this level
  ++outcome.cutbacks;
  Eigen::VectorXd& half = halfState_[level];
  return advanceLevel(z, t, 0.5 * dt, level + 1, half, outcome) &&
         advanceLevel(half, t + 0.5 * dt, 0.5 * dt, level + 1, zNew, outcome);
}

StepOutcome Integrator::advance(const Eigen::VectorXd& z, double t, double dt, Eigen::VectorXd& zNew) {
  StepOutcome outcome;
  outcome.converged = advanceLevel(z, t, dt, 0, zNew, outcome);
  return outcome;
}

}  // namespace mpx
