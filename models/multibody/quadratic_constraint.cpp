#include "models/multibody/quadratic_constraint.hpp"

#include <algorithm>
#include <cassert>
#include <cmath>
#include <stdexcept>
#include <utility>

namespace mpx {

std::vector<int> QuadraticConstraint::collectDofs(const ConstraintSpec& spec) {
  std::vector<int> dofs = spec.positionDofs;
  for (int p : spec.positionDofs) dofs.push_back(p + spec.velocityShift);
  // lambda_k then mu_k (augmented Lagrangian only)
  if (spec.enforcement == Enforcement::AugmentedLagrangian)
    for (std::size_t k = 0; k < 2 * spec.forms.size(); ++k)
      dofs.push_back(spec.firstMultiplierDof + static_cast<int>(k));
  return dofs;
}

QuadraticConstraint::QuadraticConstraint(ConstraintSpec spec)
    : Component(spec.name, collectDofs(spec)),
      spec_(std::move(spec)),
      positionCount_(static_cast<int>(spec_.positionDofs.size())),
      implied_(spec_.forms.size(), false) {
  if (positionCount_ > kMaxConstrainedDofs)
    throw std::logic_error("constraint '" + name() + "' couples more than kMaxConstrainedDofs positions");
  for (const QuadraticForm& form : spec_.forms)
    for (int a = 0; a < positionCount_; ++a) {
      if (form.touches(a)) sharesAForm_[a] |= form.support();
      sharesAHessian_[a] |= form.hessianRow(a);
    }
}

ConstraintVector QuadraticConstraint::gather(const double* z, int shift) const {
  ConstraintVector q(positionCount_);
  for (int i = 0; i < positionCount_; ++i) q[i] = z[spec_.positionDofs[i] + shift];
  return q;
}

// A form's terms reach the coordinates it touches: the momentum rows of those coordinates get
// (lambda + kappa Phi) grad Phi and its Hessian, lambda's row Phi or its rate; mu's row is mu = 0
// outside the rate form, where it is G v = 0 (the velocities it touches, the positions through
// H v) and mu grad Phi enters the kinematic rows (mu's column, the positions through mu H).
bool QuadraticConstraint::couples(int row, int column, LocalForm form) const {
  const int n = positionCount_, m = static_cast<int>(spec_.forms.size());
  enum class Kind { Position, Velocity, Lambda, Mu };
  auto split = [&](int local) -> std::pair<Kind, int> {
    if (local < n) return {Kind::Position, local};
    if (local < 2 * n) return {Kind::Velocity, local - n};
    return local < 2 * n + m ? std::pair{Kind::Lambda, local - 2 * n} : std::pair{Kind::Mu, local - 2 * n - m};
  };
  const auto [rowKind, r] = split(row);
  const auto [columnKind, c] = split(column);
  auto touches = [&](int k, int coordinate) { return spec_.forms[k].touches(coordinate); };
  auto shareAForm = [&](int a, int b) { return (sharesAForm_[a] >> b & 1u) != 0; };
  auto shareAHessian = [&](int a, int b) { return (sharesAHessian_[a] >> b & 1u) != 0; };
  const bool rate = form == LocalForm::Rate;
  switch (rowKind) {
    case Kind::Velocity:
      return (columnKind == Kind::Position && shareAForm(r, c)) || (columnKind == Kind::Lambda && touches(c, r));
    case Kind::Position:
      return rate && augmented() &&
             ((columnKind == Kind::Position && shareAHessian(r, c)) || (columnKind == Kind::Mu && touches(c, r)));
    case Kind::Lambda:
      return (columnKind == Kind::Position && touches(r, c)) || (columnKind == Kind::Lambda && c == r);
    case Kind::Mu:
      return (columnKind == Kind::Mu && c == r) ||
             (rate && ((columnKind == Kind::Position && spec_.forms[r].hessianRow(c) != 0) ||
                       (columnKind == Kind::Velocity && touches(r, c))));
  }
  return false;
}

double QuadraticConstraint::multiplier(const double* z, std::size_t k) const {
  return lambdaUnknown(k) ? z[spec_.firstMultiplierDof + k] : 0.0;
}

void QuadraticConstraint::spatialVectors(std::vector<SpatialVector>& out) const {
  // a gap component implied by other constraints keeps its multipliers at zero: not turned
  if (augmented() && spec_.leadingGap && !implied_[0] && !implied_[1] && !implied_[2])
    out.push_back({spec_.firstMultiplierDof, spec_.firstMultiplierDof + static_cast<int>(spec_.forms.size()),
                   SpatialVector::Kind::Force});
}

void QuadraticConstraint::measure(const double* z, Measures& out) const {
  const ConstraintVector q = gather(z, 0);
  for (std::size_t k = 0; k < spec_.forms.size(); ++k) {
    const double phi = spec_.forms[k].valueAt(q);
    out.energy += multiplier(z, k) * phi + 0.5 * spec_.stiffness * phi * phi;
    out.constraintViolation = std::max(out.constraintViolation, std::abs(phi));
  }
}

void QuadraticConstraint::eemLocal(const StepArgs& args, Workspace&, LocalSystem& out, Flows&) const {
  const ConstraintVector q0 = gather(args.zOld, 0), q1 = gather(args.zNew, 0);
  const int n = positionCount_, m = static_cast<int>(spec_.forms.size());
  auto r = out.residual();
  auto K = out.tangent();
  for (int k = 0; k < m; ++k) {
    const QuadraticForm& form = spec_.forms[k];
    const int supportSize = static_cast<int>(form.supportCoordinates().size());
    // exact discrete gradient of lambda Phi + kappa/2 Phi^2 for a quadratic Phi: the gradient at
    // the midpoint, the mean of the end points' (two products with H, not three)
    SupportValues gradientStart, gradientEnd, gradientMid;
    const double phiStart = form.valueAndSupportGradient(q0, gradientStart);
    const double phiEnd = form.valueAndSupportGradient(q1, gradientEnd);
    const double force = multiplier(args.zNew, k) + 0.5 * spec_.stiffness * (phiStart + phiEnd);
    for (int s = 0; s < supportSize; ++s) gradientMid[s] = 0.5 * (gradientStart[s] + gradientEnd[s]);
    form.addOnSupport(force, gradientMid, r.segment(n, n));
    // the tangent takes the gradients whole
    ConstraintVector wholeMid, wholeEnd;
    if (args.tangent) {
      wholeMid = form.fromSupport(gradientMid);
      wholeEnd = form.fromSupport(gradientEnd);
      K.block(n, 0, n, n).noalias() += (0.5 * spec_.stiffness) * wholeMid * wholeEnd.transpose();
      form.addHessian(0.5 * force, K.block(n, 0, n, n));
    }
    if (!augmented()) continue;
    // mu is not used by EEM (mu = 0), nor lambda of an implied form
    const int lambda = 2 * n + k, mu = 2 * n + m + k;
    r[mu] = args.zNew[spec_.firstMultiplierDof + m + k];
    if (implied_[k]) {
      r[lambda] = args.zNew[spec_.firstMultiplierDof + k];
      if (args.tangent) K(mu, mu) = K(lambda, lambda) = 1.0;
      continue;
    }
    // lambda's row: the constraint at the end of the step
    r[lambda] = phiEnd;
    if (!args.tangent) continue;
    K(mu, mu) = 1.0;
    K.block(n, lambda, n, 1) += wholeMid;
    K.block(lambda, 0, 1, n) = wholeEnd.transpose();
  }
}

void QuadraticConstraint::rateLocal(const RateArgs& args, Workspace&, LocalSystem& out, Flows&) const {
  const ConstraintVector q = gather(args.z, 0), v = gather(args.z, spec_.velocityShift);
  const int n = positionCount_, m = static_cast<int>(spec_.forms.size());
  auto r = out.residual();
  auto K = out.tangent();
  // the tangent only where it has a z-part (not in IDA's residual calls)
  const bool positionTangent = args.alpha != 0.0;
  for (int k = 0; k < m; ++k) {
    const QuadraticForm& form = spec_.forms[k];
    SupportValues supportGradient;
    const double phi = form.valueAndSupportGradient(q, supportGradient);
    const double force = multiplier(args.z, k) + spec_.stiffness * phi;
    form.addOnSupport(force, supportGradient, r.segment(n, n));
    const ConstraintVector gradient = positionTangent ? form.fromSupport(supportGradient) : ConstraintVector();
    if (positionTangent) {
      K.block(n, 0, n, n).noalias() += (args.alpha * spec_.stiffness) * gradient * gradient.transpose();
      form.addHessian(args.alpha * force, K.block(n, 0, n, n));
    }
    if (!augmented()) continue;
    // GGL (index 2): M v' + (lambda + kappa Phi) G^T = f, q' - v + mu G^T = 0, Phi = 0, G v = 0
    const int lambda = 2 * n + k, mu = 2 * n + m + k;
    const double muValue = args.z[spec_.firstMultiplierDof + m + k];
    // an implied form's multipliers are held at zero: lambda = mu = 0
    if (implied_[k]) {
      r[lambda] = args.z[spec_.firstMultiplierDof + k];
      r[mu] = muValue;
      if (positionTangent) K(lambda, lambda) = K(mu, mu) = args.alpha;
      continue;
    }
    form.addOnSupport(muValue, supportGradient, r.segment(0, n));
    r[lambda] = phi;
    r[mu] = form.dotOnSupport(supportGradient, v);  // grad Phi . v
    // every multiplier entry of the tangent is alpha times a derivative (none in IDA's residual calls)
    if (!positionTangent) continue;
    form.addHessian(args.alpha * muValue, K.block(0, 0, n, n));
    K.block(n, lambda, n, 1) += args.alpha * gradient;
    K.block(0, mu, n, 1) += args.alpha * gradient;
    K.block(lambda, 0, 1, n) = args.alpha * gradient.transpose();
    K.block(mu, 0, 1, n) = args.alpha * form.hessianTimes(v).transpose();
    K.block(mu, n, 1, n) = args.alpha * gradient.transpose();
  }
}

void QuadraticConstraint::stageLocal(const StageArgs& args, Workspace&, LocalSystem& out, Flows&) const {
  addStages(args, args.stage, 1, &out);
}

void QuadraticConstraint::stageResiduals(const StageArgs& args, Workspace&, LocalSystem* out, Flows*) const {
  addStages(args, 0, args.rule->stages, out);
}

// The step's path at the points of the fine rule, which every form and stage share.
struct QuadraticConstraint::StagePath {
  ConstraintVector q[CollocationRule::kFinePoints], rate[CollocationRule::kFinePoints];  // positions, tau-rates
  // the line through the stages' positions (q's projection onto linear functions of tau), where
  // the multipliers' forces take grad Phi
  ConstraintVector line[CollocationRule::kFinePoints];
  ConstraintVector start, end;  // positions at the step's start and end
  // each stage's test function times the fine rule's weight, over the stage's Gauss weight
  double testWeight[CollocationRule::kFinePoints][CollocationRule::kMostStages];
};

// One form's Galerkin projections onto the stages' test functions, exact for these polynomial
// integrands: the constraint force (on the form's support) and, for lambda's row, the rate of
// Phi; with a tangent (one stage at a time) the n x n block, the Hessian's share
// of it summed over the points before it multiplies H, lambda's column and row.
struct QuadraticConstraint::StageProjection {
  bool lambdaUnknown = false;  // lambda_k is a stagewise linear unknown
  SupportValues force[CollocationRule::kMostStages];
  double rateOfPhi[CollocationRule::kMostStages] = {};
  ConstraintMatrix dForce;
  ConstraintVector dForceDLambda, rateRow;
  double hessianWeight = 0.0;
};

void QuadraticConstraint::addStages(const StageArgs& args, int firstStage, int count, LocalSystem* out) const {
  assert(!args.tangent || count == 1);  // the projections' tangent sums serve one stage
  const StagePath path = stagePath(args, firstStage, count);
  for (std::size_t k = 0; k < spec_.forms.size(); ++k)
    addFormRows(k, project(k, args, path, count), args, path, firstStage, count, out);
}

QuadraticConstraint::StagePath QuadraticConstraint::stagePath(const StageArgs& args, int firstStage, int count) const {
  const CollocationRule& rule = *args.rule;
  const int n = positionCount_;
  StagePath path;
  // the basis points of the step's polynomial: the start, then each stage
  ConstraintVector basis[CollocationRule::kMostStages + 1];
  basis[0] = path.start = gather(args.zOld, 0);
  for (int j = 0; j < rule.stages; ++j) basis[j + 1] = gather(args.stageState[j], 0);
  path.end = gather(args.zEnd, 0);
  for (int p = 0; p < CollocationRule::kFinePoints; ++p) {
    path.q[p] = path.rate[p] = path.line[p] = ConstraintVector::Zero(n);
    for (int j = 0; j <= rule.stages; ++j) {
      path.q[p] += rule.fineValue[p][j] * basis[j];
      path.rate[p] += rule.fineRate[p][j] * basis[j];
    }
    if (augmented())
      for (int j = 0; j < rule.stages; ++j) path.line[p] += rule.fineStage[p][j] * basis[j + 1];
    for (int i = 0; i < count; ++i) {
      const int l = firstStage + i;
      path.testWeight[p][i] = rule.fineWeight[p] * rule.fineStage[p][l] / rule.weight[l];
    }
  }
  return path;
}

QuadraticConstraint::StageProjection QuadraticConstraint::project(std::size_t k, const StageArgs& args,
                                                                  const StagePath& path, int count) const {
  const CollocationRule& rule = *args.rule;
  const int column = args.column, n = positionCount_;
  const QuadraticForm& form = spec_.forms[k];
  StageProjection out;
  out.lambdaUnknown = lambdaUnknown(k);
  const int supportSize = static_cast<int>(form.supportCoordinates().size());
  for (int i = 0; i < count; ++i) std::fill_n(out.force[i].begin(), supportSize, 0.0);
  if (args.tangent) {
    out.dForce.setZero(n, n);
    out.dForceDLambda = out.rateRow = ConstraintVector::Zero(n);
  }
  // Under the augmented Lagrangian the force (lambda + kappa (Phi_0 + Phi_end) / 2) grad Phi takes
  // grad Phi on the stages' line y, whose moment y x grad Phi(y) vanishes pointwise for the
  // rigidity's forms (section 13.7); the penalty's mean over the step's ends is its discrete
  // gradient in Phi (lambda = 0 on an implied form). A penalty alone takes kappa Phi grad Phi on
  // the path, whose change of kappa/2 Phi^2 is exact.
  const bool onLine = augmented();
  double lambda[CollocationRule::kMostStages] = {}, meanPenalty = 0.0;
  SupportValues endGradient{};
  if (out.lambdaUnknown)
    for (int j = 0; j < rule.stages; ++j) lambda[j] = args.stageState[j][spec_.firstMultiplierDof + k];
  if (onLine) {
    const double phiEnd = form.valueAndSupportGradient(path.end, endGradient);
    meanPenalty = 0.5 * spec_.stiffness * (form.valueAt(path.start) + phiEnd);
  }
  ConstraintVector lineForce = args.tangent ? ConstraintVector::Zero(n) : ConstraintVector();
  for (int p = 0; p < CollocationRule::kFinePoints; ++p) {
    double value = meanPenalty;
    for (int j = 0; j < rule.stages; ++j) value += rule.fineStage[p][j] * lambda[j];
    SupportValues gradientHere;
    if (onLine)
      form.valueAndSupportGradient(path.line[p], gradientHere);
    else
      value = spec_.stiffness * form.valueAndSupportGradient(path.q[p], gradientHere);
    const double rateOfPhiHere = out.lambdaUnknown ? form.dotOnSupport(gradientHere, path.rate[p]) : 0.0;
    const ConstraintVector gradient = args.tangent ? form.fromSupport(gradientHere) : ConstraintVector();
    for (int i = 0; i < count; ++i) {
      const double test = path.testWeight[p][i];
      for (int s = 0; s < supportSize; ++s) out.force[i][s] += (test * value) * gradientHere[s];
      out.rateOfPhi[i] += test * rateOfPhiHere;
      if (!args.tangent) continue;
      if (!onLine) {
        // d q / d Z_column at this point
        const double valueCoefficient = rule.fineValue[p][column + 1];
        out.hessianWeight += test * valueCoefficient * value;
        out.dForce.noalias() += (test * valueCoefficient * spec_.stiffness) * gradient * gradient.transpose();
        continue;
      }
      // d y / d Z_column at this point
      const double lineCoefficient = rule.fineStage[p][column];
      out.hessianWeight += test * lineCoefficient * value;
      lineForce += test * gradient;
      if (!out.lambdaUnknown) continue;
      out.dForceDLambda += (test * lineCoefficient) * gradient;
      out.rateRow +=
          test * (lineCoefficient * form.hessianTimes(path.rate[p]) + rule.fineRate[p][column + 1] * gradient);
    }
  }
  // the mean penalty's change with the step's end
  if (args.tangent && onLine)
    out.dForce.noalias() +=
        (0.5 * spec_.stiffness * rule.end[column + 1]) * lineForce * form.fromSupport(endGradient).transpose();
  return out;
}

void QuadraticConstraint::addFormRows(std::size_t k, const StageProjection& projection, const StageArgs& args,
                                      const StagePath& path, int firstStage, int count, LocalSystem* out) const {
  const CollocationRule& rule = *args.rule;
  const int column = args.column, n = positionCount_, m = static_cast<int>(spec_.forms.size());
  const QuadraticForm& form = spec_.forms[k];
  for (int i = 0; i < count; ++i) {
    const int l = firstStage + i;
    const bool own = args.tangent && l == column;
    const double* z = args.stageState[l];
    auto r = out[i].residual();
    auto K = out[i].tangent();
    form.addOnSupport(1.0, projection.force[i], r.segment(n, n));
    if (args.tangent) {
      K.block(n, 0, n, n) += projection.dForce;
      form.addHessian(projection.hessianWeight, K.block(n, 0, n, n));
    }
    if (!augmented()) continue;
    // mu is not used (mu = 0), nor lambda of an implied form
    const int lambdaRow = 2 * n + static_cast<int>(k), mu = 2 * n + m + static_cast<int>(k);
    r[mu] = z[spec_.firstMultiplierDof + m + k];
    if (own) K(mu, mu) = 1.0;
    if (!projection.lambdaUnknown) {
      r[lambdaRow] = z[spec_.firstMultiplierDof + k];
      if (own) K(lambdaRow, lambdaRow) = 1.0;
      continue;
    }
    if (args.tangent) K.block(n, lambdaRow, n, 1) += projection.dForceDLambda;
    // lambda's rows: Phi(q_end) = 0 at the first stage, grad Phi(y) . q' tested with the later
    // stages' test functions. Its integral over the step is Phi(q_end) - Phi(q_0) (q - y is a
    // multiple of the second Legendre polynomial, orthogonal to the linear H q'), so the forces
    // do the work lambda_1 (Phi(q_end) - Phi(q_0)) = 0 over the step (docs/theory.md section 13.7)
    if (l == 0) {
      SupportValues gradientEnd;
      r[lambdaRow] = form.valueAndSupportGradient(path.end, gradientEnd);
      if (args.tangent) K.block(lambdaRow, 0, 1, n) = rule.end[column + 1] * form.fromSupport(gradientEnd).transpose();
    } else {
      r[lambdaRow] = projection.rateOfPhi[i] / args.dt;
      if (args.tangent) K.block(lambdaRow, 0, 1, n) = projection.rateRow.transpose() / args.dt;
    }
  }
}

}  // namespace mpx
