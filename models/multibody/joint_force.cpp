#include "models/multibody/joint_force.hpp"

#include "engine/core/stage_gradient.hpp"

#include <cmath>

namespace mpx {

namespace {
constexpr int kInternal = 2;  // argument slot of the internal variable

// k (1 - cos(theta - angle)) with theta = atan2(v, u), as k (1 - (u cos a + v sin a)/r) in
// (u, v, angle): smooth in all three, no wrap-around.
Jet cosineEnergy(double k, double u, double v, double angle) {
  const double c = std::cos(angle), s = std::sin(angle);
  const double r2 = u * u + v * v, r = std::sqrt(r2), r3 = r2 * r, r5 = r3 * r2;
  const double w = c * u + s * v, wAngle = -s * u + c * v;  // w and dw/dangle
  Jet f;                                                    // f = w / r
  f.value = w / r;
  f.grad = Vec3(c / r - w * u / r3, s / r - w * v / r3, wAngle / r);
  f.hess(0, 0) = -2.0 * c * u / r3 - w / r3 + 3.0 * w * u * u / r5;
  f.hess(1, 1) = -2.0 * s * v / r3 - w / r3 + 3.0 * w * v * v / r5;
  f.hess(0, 1) = f.hess(1, 0) = -(c * v + s * u) / r3 + 3.0 * w * u * v / r5;
  f.hess(2, 2) = -w / r;
  f.hess(0, 2) = f.hess(2, 0) = -s / r - wAngle * u / r3;
  f.hess(1, 2) = f.hess(2, 1) = c / r - wAngle * v / r3;
  Jet jet;
  jet.value = k * (1.0 - f.value);
  jet.grad = -k * f.grad;
  jet.hess = -k * f.hess;
  return jet;
}
}  // namespace

std::vector<int> JointForce::collectDofs(const JointForceSpec& spec) {
  std::vector<int> dofs = spec.positionDofs;
  for (int p : spec.positionDofs) dofs.push_back(p + spec.velocityShift);
  if (spec.heatDof >= 0) dofs.push_back(spec.heatDof);
  if (spec.internalDof >= 0) dofs.push_back(spec.internalDof);
  return dofs;
}

JointForce::JointForce(JointForceSpec spec)
    : Component(spec.name, collectDofs(spec)),
      spec_(std::move(spec)),
      n_(static_cast<int>(spec_.positionDofs.size())),
      localHeat_(spec_.heatDof >= 0 ? 2 * n_ : -1),
      localInternal_(spec_.internalDof >= 0 ? 2 * n_ + (spec_.heatDof >= 0 ? 1 : 0) : -1) {}

ConstraintVector JointForce::gather(const double* z, int shift) const {
  ConstraintVector q(n_);
  for (int i = 0; i < n_; ++i) q[i] = z[spec_.positionDofs[i] + shift];
  return q;
}

Vec3 JointForce::arguments(const double* z) const {
  const ConstraintVector q = gather(z, 0);
  Vec3 args = Vec3::Zero();
  for (std::size_t a = 0; a < spec_.invariants.size(); ++a) args[a] = spec_.invariants[a].valueAt(q);
  if (localInternal_ >= 0) args[kInternal] = z[spec_.internalDof];
  return args;
}

JointForce::ArgumentJacobian JointForce::invariantJacobian(const ConstraintVector& q) const {
  ArgumentJacobian jacobian = ArgumentJacobian::Zero(3, n_);
  for (std::size_t a = 0; a < spec_.invariants.size(); ++a)
    jacobian.row(a) = spec_.invariants[a].gradientAt(q).transpose();
  return jacobian;
}

unsigned JointForce::mask() const { return (spec_.revolute ? 3u : 1u) | (localInternal_ >= 0 ? 4u : 0u); }

Jet JointForce::springEnergy(const Vec3& args) const {
  const double k = spec_.stiffness, kb = spec_.branchStiffness;
  if (spec_.revolute) {
    // spring k (1 - cos(theta - theta0)) and branch kb (1 - cos(theta - gamma))
    Jet jet = cosineEnergy(k, args[0], args[1], spec_.rest);
    jet.grad[kInternal] = 0.0;
    jet.hess.row(kInternal).setZero();
    jet.hess.col(kInternal).setZero();
    if (localInternal_ < 0) return jet;
    const Jet branch = cosineEnergy(kb, args[0], args[1], args[kInternal]);
    jet.value += branch.value;
    jet.grad += branch.grad;
    jet.hess += branch.hess;
    return jet;
  }
  // k/2 e^2 + k3/4 e^4 with e = s - s0, and kb/2 (s - gamma)^2
  const double e = args[0] - spec_.rest, k3 = spec_.cubicStiffness;
  Jet jet;
  jet.value = 0.5 * k * e * e + 0.25 * k3 * e * e * e * e;
  jet.grad[0] = k * e + k3 * e * e * e;
  jet.hess(0, 0) = k + 3.0 * k3 * e * e;
  if (localInternal_ < 0) return jet;
  const double slip = args[0] - args[kInternal];
  jet.value += 0.5 * kb * slip * slip;
  jet.grad[0] += kb * slip;
  jet.grad[kInternal] = -kb * slip;
  jet.hess(0, 0) += kb;
  jet.hess(kInternal, kInternal) = kb;
  jet.hess(0, kInternal) = jet.hess(kInternal, 0) = -kb;
  return jet;
}

namespace {
// The coordinate minus the middle of the stops' range, for a revolute angle in a chart
// centred on that middle (smooth up to half a turn away).
Jet fromRangeMiddle(bool revolute, const Vec3& args, const JointStop& stop) {
  const double middle = 0.5 * (stop.lower + stop.upper);
  if (!revolute) {
    Jet jet = jointCoordinateChart(false, args, args);
    jet.value -= middle;
    return jet;
  }
  return jointCoordinateChart(true, args, Vec3(std::cos(middle), std::sin(middle), 0.0));
}
}  // namespace

JointForce::Penetration JointForce::penetration(const Vec3& args) const {
  const Jet offset = fromRangeMiddle(spec_.revolute, args, *spec_.stop);
  const double depth = std::abs(offset.value) - 0.5 * (spec_.stop->upper - spec_.stop->lower);
  if (!(depth > 0.0)) return {};
  const double sign = offset.value > 0.0 ? 1.0 : -1.0;
  return {depth, sign * offset.grad, sign * offset.hess};
}

Jet JointForce::stopEnergy(const Vec3& args) const {
  const Penetration p = penetration(args);
  const double k = spec_.stop->stiffness, d = p.depth;
  Jet jet;
  jet.value = k / 3.0 * d * d * d;
  jet.grad = k * d * d * p.grad;
  jet.hess = 2.0 * k * d * p.grad * p.grad.transpose() + k * d * d * p.hess;
  return jet;
}

Jet JointForce::energy(const Vec3& args) const {
  Jet jet = springEnergy(args);
  if (!spec_.stop) return jet;
  const Jet stop = stopEnergy(args);
  jet.value += stop.value;
  jet.grad += stop.grad;
  jet.hess += stop.hess;
  return jet;
}

double JointForce::dissipativeForce(double rate, double* dForce) const {
  const double slip = std::tanh(rate / spec_.frictionVelocity);
  *dForce = spec_.damping + spec_.friction * (1.0 - slip * slip) / spec_.frictionVelocity;
  return spec_.damping * rate + spec_.friction * slip;
}

void JointForce::deposit(double power, const ConstraintRow& dPowerDq, const ConstraintRow& dPowerDv,
                         double dPowerDgamma, LocalSystem& out, Flows& flows) const {
  // the dissipated power heats the node, or leaves the system
  if (localHeat_ < 0) {
    flows.dissipated += power;
    return;
  }
  out.residual()[localHeat_] -= power;
  out.tangent().block(localHeat_, 0, 1, n_) -= dPowerDq;
  out.tangent().block(localHeat_, n_, 1, n_) -= dPowerDv;
  if (localInternal_ >= 0) out.tangent()(localHeat_, localInternal_) -= dPowerDgamma;
}

void JointForce::measure(const double* z, Measures& out) const { out.energy += energy(arguments(z)).value; }

void JointForce::eemLocal(const StepArgs& args, Workspace&, LocalSystem& out, Flows& flows) const {
  const ConstraintVector q0 = gather(args.zOld, 0), q1 = gather(args.zNew, 0), qMid = 0.5 * (q0 + q1);
  const Vec3 a0 = arguments(args.zOld), a1 = arguments(args.zNew);
  const int m = static_cast<int>(spec_.invariants.size());
  const ArgumentJacobian J1 = invariantJacobian(q1), JMid = invariantJacobian(qMid);
  auto r = out.residual();
  auto K = out.tangent();

  // discrete gradients of the energy (invariants and gamma) and of the coordinate (chart
  // centred on the start of the step)
  const Vec3 scale = Vec3::Ones();
  const DiscreteGradient dEnergy = partitionedGradient([&](const Vec3& a) { return energy(a); }, mask(), a0, a1, scale);
  const unsigned coordinateMask = spec_.revolute ? 3u : 1u;
  const DiscreteGradient dCoordinate = partitionedGradient(
      [&](const Vec3& a) { return jointCoordinateChart(spec_.revolute, a, a0); }, coordinateMask, a0, a1, scale);
  const Jet coordinateEnd = jointCoordinateChart(spec_.revolute, a1, a0);
  const double rate = (coordinateEnd.value - jointCoordinateChart(spec_.revolute, a0, a0).value) / args.dt;
  const ConstraintRow dRate = (coordinateEnd.grad.transpose() * J1) / args.dt;
  double dForce = 0.0;
  double force = dissipativeForce(rate, &dForce);
  ConstraintRow dForceDq = dForce * dRate;
  if (spec_.stop) {
    // stop damping c_s (delta^2 + delta'^2)/2 times the rate: non-negative work like the damper's
    const Penetration p0 = penetration(a0), p1 = penetration(a1);
    const double c = spec_.stop->damping, coefficient = 0.5 * c * (p0.depth * p0.depth + p1.depth * p1.depth);
    force += coefficient * rate;
    dForceDq += coefficient * dRate + (c * rate * p1.depth) * (p1.grad.transpose() * J1);
  }
  const Vec3 forceOnArguments = dEnergy.grad + force * dCoordinate.grad;
  // the rows of J for unused slots (and gamma) are zero: only invariants push on q
  r.segment(n_, n_) += JMid.transpose() * forceOnArguments;

  // tangent w.r.t. q1 through I1 in the discrete gradients, the rate, and grad I(q_mid)
  K.block(n_, 0, n_, n_) += JMid.transpose() * (dEnergy.dGradDb + force * dCoordinate.dGradDb) * J1 +
                            JMid.transpose() * dCoordinate.grad * dForceDq;
  for (int a = 0; a < m; ++a) spec_.invariants[a].addHessian(0.5 * forceOnArguments[a], K.block(n_, 0, n_, n_));

  // Maxwell branch: nu (gamma' - gamma)/dt = -D_gamma e, dissipating (D_gamma e)^2 / nu
  double power = force * rate;
  ConstraintRow dPowerDq = rate * dForceDq + force * dRate;
  double dPowerDgamma = 0.0;
  if (localInternal_ >= 0) {
    const double nu = spec_.viscosity, g = -dEnergy.grad[kInternal];
    const ConstraintRow dgDq = -dEnergy.dGradDb.row(kInternal) * J1;
    const double dgDgamma = -dEnergy.dGradDb(kInternal, kInternal);
    K.block(n_, localInternal_, n_, 1) += JMid.transpose() * dEnergy.dGradDb.col(kInternal);
    r[localInternal_] = nu * (a1[kInternal] - a0[kInternal]) / args.dt - g;
    K.block(localInternal_, 0, 1, n_) -= dgDq;
    K(localInternal_, localInternal_) += nu / args.dt - dgDgamma;
    power += g * g / nu;
    dPowerDq += (2.0 * g / nu) * dgDq;
    dPowerDgamma = 2.0 * g / nu * dgDgamma;
  }

  deposit(power, dPowerDq, ConstraintRow::Zero(n_), dPowerDgamma, out, flows);
}

double JointForce::addDissipativeForce(const Vec3& a, const ConstraintVector& v, const ArgumentJacobian& J,
                                       double alpha, LocalSystem& out, ConstraintRow& dPowerDq,
                                       ConstraintRow& dPowerDv) const {
  const int m = static_cast<int>(spec_.invariants.size());
  const Jet angle = jointCoordinateChart(spec_.revolute, a, a);
  const Vec3 invariantRate = J * v;
  const double rate = angle.grad.dot(invariantRate);
  // d rate/dq through I (Hessian of the coordinate) and through J (Hessians of I); d rate/dv
  ConstraintRow dRateDq = (angle.hess * invariantRate).transpose() * J;
  for (int i = 0; i < m; ++i) dRateDq += angle.grad[i] * spec_.invariants[i].hessianTimes(v).transpose();
  const ConstraintRow dRateDv = angle.grad.transpose() * J;
  double dForce = 0.0;
  double force = dissipativeForce(rate, &dForce);
  ConstraintRow dForceDq = dForce * dRateDq, dForceDv = dForce * dRateDv;
  if (spec_.stop) {
    // stop damping c_s delta^2 times the rate
    const Penetration p = penetration(a);
    const double c = spec_.stop->damping, coefficient = c * p.depth * p.depth;
    force += coefficient * rate;
    dForceDq += coefficient * dRateDq + (2.0 * c * rate * p.depth) * (p.grad.transpose() * J);
    dForceDv += coefficient * dRateDv;
  }
  auto K = out.tangent();
  const ConstraintVector direction = J.transpose() * angle.grad;
  out.residual().segment(n_, n_) += force * direction;
  K.block(n_, 0, n_, n_) += alpha * (force * J.transpose() * angle.hess * J + direction * dForceDq);
  K.block(n_, n_, n_, n_) += alpha * direction * dForceDv;
  for (int i = 0; i < m; ++i) spec_.invariants[i].addHessian(alpha * force * angle.grad[i], K.block(n_, 0, n_, n_));
  dPowerDq = alpha * (rate * dForceDq + force * dRateDq);
  dPowerDv = alpha * (rate * dForceDv + force * dRateDv);
  return force * rate;
}

void JointForce::rateLocal(const RateArgs& args, Workspace&, LocalSystem& out, Flows& flows) const {
  const ConstraintVector q = gather(args.z, 0);
  const Vec3 a = arguments(args.z);
  const int m = static_cast<int>(spec_.invariants.size());
  const ArgumentJacobian J = invariantJacobian(q);
  const Jet e = energy(a);
  auto r = out.residual();
  auto K = out.tangent();
  r.segment(n_, n_) += J.transpose() * e.grad;
  K.block(n_, 0, n_, n_) += args.alpha * J.transpose() * e.hess * J;
  for (int i = 0; i < m; ++i) spec_.invariants[i].addHessian(args.alpha * e.grad[i], K.block(n_, 0, n_, n_));
  // the coordinate rate from the velocities, not from the position rates: under constraints the
  // GGL kinematic rows make q' = v - mu dPhi/dq, and a stiff damper on q' would amplify the
  // index-2 multiplier mu into the momentum rows (docs/theory.md section 6.2)
  ConstraintRow dPowerDq, dPowerDv;
  double power = addDissipativeForce(a, gather(args.z, spec_.velocityShift), J, args.alpha, out, dPowerDq, dPowerDv);
  double dPowerDgamma = 0.0;
  if (localInternal_ >= 0) {
    // nu gamma' = -de/dgamma, dissipating (de/dgamma)^2 / nu
    const double nu = spec_.viscosity, g = -e.grad[kInternal];
    const ConstraintRow dgDq = -e.hess.row(kInternal) * J;
    K.block(n_, localInternal_, n_, 1) += args.alpha * J.transpose() * e.hess.col(kInternal);
    r[localInternal_] = nu * args.zdot[spec_.internalDof] - g;
    K.block(localInternal_, 0, 1, n_) -= args.alpha * dgDq;
    K(localInternal_, localInternal_) += args.beta * nu + args.alpha * e.hess(kInternal, kInternal);
    power += g * g / nu;
    dPowerDq += args.alpha * (2.0 * g / nu) * dgDq;
    dPowerDgamma = -args.alpha * (2.0 * g / nu) * e.hess(kInternal, kInternal);
  }
  deposit(power, dPowerDq, dPowerDv, dPowerDgamma, out, flows);
}

void JointForce::argumentRows(const double* z, int count, LocalRow (&rows)[3]) const {
  const ConstraintVector q = gather(z, 0);
  for (LocalRow& row : rows) row = LocalRow::Zero(count);
  for (std::size_t i = 0; i < spec_.invariants.size(); ++i)
    rows[i].head(n_) = spec_.invariants[i].gradientAt(q).transpose();
  if (localInternal_ >= 0) rows[kInternal][localInternal_] = 1.0;
}

void JointForce::stageLocal(const StageArgs& args, Workspace&, LocalSystem& out, Flows& flows) const {
  const CollocationRule& rule = *args.rule;
  const int l = args.stage, column = args.column, m = static_cast<int>(spec_.invariants.size());
  const bool own = l == column;
  // the arguments (I, gamma) along the stage polynomial, with their tau-rates
  StagePath path;
  path.column = column;
  path.start = arguments(args.zOld);
  path.end = arguments(args.zEnd);
  argumentRows(args.zEnd, out.n, path.endRows);
  for (int j = 0; j < rule.stages; ++j) {
    const ConstraintVector q = gather(args.stageState[j], 0), qRate = args.dt * gather(args.stageRate[j], 0);
    path.value[j] = arguments(args.stageState[j]);
    path.rate[j] = Vec3::Zero();
    for (int i = 0; i < m; ++i) path.rate[j][i] = spec_.invariants[i].gradientAt(q).dot(qRate);
    if (localInternal_ >= 0) path.rate[j][kInternal] = args.dt * args.stageRate[j][spec_.internalDof];
    argumentRows(args.stageState[j], out.n, path.rows[j]);
    // a'_j through the rates (coefficient rule.rate) and, for I, through grad I on its own stage
    for (int i = 0; i < 3; ++i) path.rateRows[j][i] = rule.rate[j][column + 1] * path.rows[j][i];
    if (j == column)
      for (int i = 0; i < m; ++i) path.rateRows[j][i].head(n_) += spec_.invariants[i].hessianTimes(qRate).transpose();
  }
  const GradientRows dEnergy =
      consistentGradient([&](const Vec3& a) { return energy(a); }, mask(), Vec3::Ones(), rule, path, l);

  // the stored energy's pull at the stage, then the dissipative forces in rate form there
  const double* z = args.stageState[l];
  const ConstraintVector q = gather(z, 0);
  const ArgumentJacobian J = invariantJacobian(q);
  auto r = out.residual();
  auto K = out.tangent();
  r.segment(n_, n_) += J.transpose() * dEnergy.grad;
  for (int i = 0; i < m; ++i) {
    K.block(n_, 0, n_, out.n) += J.row(i).transpose() * dEnergy.d[i];
    if (own) spec_.invariants[i].addHessian(dEnergy.grad[i], K.block(n_, 0, n_, n_));
  }
  ConstraintRow dPowerDq, dPowerDv;
  double power =
      addDissipativeForce(path.value[l], gather(z, spec_.velocityShift), J, own ? 1.0 : 0.0, out, dPowerDq, dPowerDv);
  double dPowerDgamma = 0.0;
  if (localInternal_ >= 0) {
    // Maxwell branch: nu gamma' = g with g = -D_gamma e at the stage, dissipating g^2 / nu
    const double nu = spec_.viscosity, g = -dEnergy.grad[kInternal];
    const LocalRow dg = -dEnergy.d[kInternal];
    r[localInternal_] = nu * args.stageRate[l][spec_.internalDof] - g;
    K.row(localInternal_) -= dg;
    K(localInternal_, localInternal_) += nu * rule.rate[l][column + 1] / args.dt;
    power += g * g / nu;
    dPowerDq += (2.0 * g / nu) * dg.head(n_);
    dPowerDgamma = (2.0 * g / nu) * dg[localInternal_];
  }
  deposit(power, dPowerDq, dPowerDv, dPowerDgamma, out, flows);
}

}  // namespace mpx
