#include "quadratic_constraint.hpp"

#include <cmath>

namespace mpx {

std::vector<int> QuadraticConstraint::collectDofs(const ConstraintSpec& spec) {
  std::vector<int> dofs = spec.positionDofs;
  for (int p : spec.positionDofs) dofs.push_back(p + spec.velocityShift);
  if (spec.enforcement == Enforcement::AugmentedLagrangian)
    for (std::size_t k = 0; k < spec.forms.size(); ++k) dofs.push_back(spec.firstMultiplierDof + static_cast<int>(k));
  return dofs;
}

QuadraticConstraint::QuadraticConstraint(ConstraintSpec spec)
    : Component(spec.name, collectDofs(spec)),
      spec_(std::move(spec)),
      positionCount_(static_cast<int>(spec_.positionDofs.size())) {}

ConstraintVector QuadraticConstraint::positions(const double* z) const {
  ConstraintVector q(positionCount_);
  for (int i = 0; i < positionCount_; ++i) q[i] = z[spec_.positionDofs[i]];
  return q;
}

double QuadraticConstraint::multiplier(const double* z, std::size_t k) const {
  return augmented() ? z[spec_.firstMultiplierDof + k] : 0.0;
}

void QuadraticConstraint::holdMultipliers(LocalSystem& out, double diagonal) const {
  if (!augmented()) return;
  for (std::size_t k = 0; k < spec_.forms.size(); ++k) {
    const int row = 2 * positionCount_ + static_cast<int>(k);
    out.tangent()(row, row) = diagonal;
  }
}

void QuadraticConstraint::measure(const double* z, Measures& out) const {
  const ConstraintVector q = positions(z);
  for (std::size_t k = 0; k < spec_.forms.size(); ++k) {
    const double phi = spec_.forms[k].value(q);
    out.energy += multiplier(z, k) * phi + 0.5 * spec_.stiffness * phi * phi;
    out.constraintViolation = std::max(out.constraintViolation, std::abs(phi));
  }
}

void QuadraticConstraint::eemLocal(const StepArgs& args, Workspace&, LocalSystem& out, Flows&) const {
  const ConstraintVector q0 = positions(args.zOld), q1 = positions(args.zNew);
  const ConstraintVector qMid = 0.5 * (q0 + q1);
  const int n = positionCount_;
  auto r = out.residual();
  auto K = out.tangent();
  for (std::size_t k = 0; k < spec_.forms.size(); ++k) {
    const QuadraticForm& form = spec_.forms[k];
    // exact discrete gradient of lambda Phi + kappa/2 Phi^2 for a quadratic Phi
    const double force = multiplier(args.zNew, k) + 0.5 * spec_.stiffness * (form.value(q0) + form.value(q1));
    const ConstraintVector gradientMid = form.gradientAt(qMid);
    r.segment(n, n) += force * gradientMid;
    K.block(n, 0, n, n) += 0.5 * force * form.hessian +
                           (0.5 * spec_.stiffness) * gradientMid * form.gradientAt(q1).transpose();
    if (!augmented()) continue;
    // the multiplier's own row: the constraint at the end of the step
    const int row = 2 * n + static_cast<int>(k);
    K.block(n, row, n, 1) += gradientMid;
    r[row] = form.value(q1);
    K.block(row, 0, 1, n) = form.gradientAt(q1).transpose();
  }
}

void QuadraticConstraint::rateLocal(const RateArgs& args, Workspace&, LocalSystem& out, Flows&) const {
  const ConstraintVector q = positions(args.z);
  const int n = positionCount_;
  auto r = out.residual();
  auto K = out.tangent();
  for (std::size_t k = 0; k < spec_.forms.size(); ++k) {
    const QuadraticForm& form = spec_.forms[k];
    const double force = multiplier(args.z, k) + spec_.stiffness * form.value(q);
    const ConstraintVector gradient = form.gradientAt(q);
    r.segment(n, n) += force * gradient;
    K.block(n, 0, n, n) += args.alpha * (force * form.hessian + spec_.stiffness * gradient * gradient.transpose());
    if (augmented()) K.block(n, 2 * n + k, n, 1) += args.alpha * gradient;
  }
  holdMultipliers(out, args.beta);
}

}  // namespace mpx
