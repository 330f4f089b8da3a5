#include "joint_force.hpp"

#include <cmath>

namespace mpx {

std::vector<int> JointForce::collectDofs(const JointForceSpec& spec) {
  std::vector<int> dofs = spec.positionDofs;
  for (int p : spec.positionDofs) dofs.push_back(p + spec.velocityShift);
  if (spec.heatDof >= 0) dofs.push_back(spec.heatDof);
  return dofs;
}

JointForce::JointForce(JointForceSpec spec)
    : Component(spec.name, collectDofs(spec)), spec_(std::move(spec)), n_(static_cast<int>(spec_.positionDofs.size())) {}

ConstraintVector JointForce::gather(const double* z, int shift) const {
  ConstraintVector q(n_);
  for (int i = 0; i < n_; ++i) q[i] = z[spec_.positionDofs[i] + shift];
  return q;
}

Vec3 JointForce::invariantsAt(const ConstraintVector& q) const {
  Vec3 invariants = Vec3::Zero();
  for (std::size_t a = 0; a < spec_.invariants.size(); ++a) invariants[a] = spec_.invariants[a].value(q);
  return invariants;
}

ConstraintMatrix JointForce::invariantJacobian(const ConstraintVector& q) const {
  ConstraintMatrix jacobian(spec_.invariants.size(), n_);
  for (std::size_t a = 0; a < spec_.invariants.size(); ++a)
    jacobian.row(a) = spec_.invariants[a].gradientAt(q).transpose();
  return jacobian;
}

Jet JointForce::spring(const Vec3& I) const {
  Jet jet;
  const double k = spec_.stiffness;
  if (!spec_.revolute) {
    // k/2 (s - s0)^2
    jet.value = 0.5 * k * (I[0] - spec_.rest) * (I[0] - spec_.rest);
    jet.grad[0] = k * (I[0] - spec_.rest);
    jet.hess(0, 0) = k;
    return jet;
  }
  // k (1 - w/r), w = u cos(theta0) + v sin(theta0), r = |(u, v)|: k (1 - cos(theta - theta0))
  const double c = std::cos(spec_.rest), s = std::sin(spec_.rest);
  const double u = I[0], v = I[1], r2 = u * u + v * v, r = std::sqrt(r2), r3 = r2 * r, r5 = r3 * r2;
  const double w = c * u + s * v;
  jet.value = k * (1.0 - w / r);
  jet.grad[0] = -k * (c / r - w * u / r3);
  jet.grad[1] = -k * (s / r - w * v / r3);
  jet.hess(0, 0) = -k * (-2.0 * c * u / r3 - w / r3 + 3.0 * w * u * u / r5);
  jet.hess(1, 1) = -k * (-2.0 * s * v / r3 - w / r3 + 3.0 * w * v * v / r5);
  jet.hess(0, 1) = jet.hess(1, 0) = -k * (-(c * v + s * u) / r3 + 3.0 * w * u * v / r5);
  return jet;
}

double JointForce::dissipativeForce(double rate, double* dForce) const {
  const double slip = std::tanh(rate / spec_.frictionVelocity);
  *dForce = spec_.damping + spec_.friction * (1.0 - slip * slip) / spec_.frictionVelocity;
  return spec_.damping * rate + spec_.friction * slip;
}

void JointForce::applyForce(const Vec3& forceOnInvariants, const ConstraintVector& qForce, LocalSystem& out) const {
  const ConstraintMatrix J = invariantJacobian(qForce);
  out.residual().segment(n_, n_) += J.transpose() * forceOnInvariants.head(J.rows());
}

void JointForce::measure(const double* z, Measures& out) const {
  out.energy += spring(invariantsAt(gather(z, 0))).value;
}

void JointForce::eemLocal(const StepArgs& args, Workspace&, LocalSystem& out, Flows& flows) const {
  const ConstraintVector q0 = gather(args.zOld, 0), q1 = gather(args.zNew, 0), qMid = 0.5 * (q0 + q1);
  const Vec3 I0 = invariantsAt(q0), I1 = invariantsAt(q1);
  const int m = static_cast<int>(spec_.invariants.size());
  const ConstraintMatrix J1 = invariantJacobian(q1), JMid = invariantJacobian(qMid);

  // discrete gradients of the spring energy and of the coordinate (chart centred on I0)
  const Vec3 scale = Vec3::Ones();
  const DiscreteGradient dSpring = partitionedGradient([&](const Vec3& I) { return spring(I); }, mask(), I0, I1, scale);
  const DiscreteGradient dCoordinate =
      partitionedGradient([&](const Vec3& I) { return jointCoordinateChart(spec_.revolute, I, I0); }, mask(), I0, I1, scale);
  const Jet coordinateEnd = jointCoordinateChart(spec_.revolute, I1, I0);
  const double rate = (coordinateEnd.value - jointCoordinateChart(spec_.revolute, I0, I0).value) / args.dt;
  double dForce = 0.0;
  const double force = dissipativeForce(rate, &dForce);
  const Vec3 forceOnInvariants = dSpring.grad + force * dCoordinate.grad;
  applyForce(forceOnInvariants, qMid, out);

  // tangent w.r.t. q1: through I1 in the discrete gradients, the rate, and grad I(q_mid)
  auto K = out.tangent();
  const ConstraintRow dRate = (coordinateEnd.grad.head(m).transpose() * J1) / args.dt;
  K.block(n_, 0, n_, n_) +=
      JMid.transpose() * (dSpring.dGradDb + force * dCoordinate.dGradDb).topLeftCorner(m, m) * J1 +
      JMid.transpose() * dCoordinate.grad.head(m) * (dForce * dRate);
  for (int a = 0; a < m; ++a) K.block(n_, 0, n_, n_) += 0.5 * forceOnInvariants[a] * spec_.invariants[a].hessian;

  // the dissipated power heats the node, or leaves the system
  const double power = force * rate;
  if (spec_.heatDof < 0) {
    flows.dissipated += power;
    return;
  }
  out.residual()[2 * n_] -= power;
  K.block(2 * n_, 0, 1, n_) -= (dForce * rate + force) * dRate;
}

void JointForce::rateLocal(const RateArgs& args, Workspace&, LocalSystem& out, Flows& flows) const {
  const ConstraintVector q = gather(args.z, 0), qRate = gather(args.zdot, 0);
  const Vec3 I = invariantsAt(q);
  const int m = static_cast<int>(spec_.invariants.size());
  const ConstraintMatrix J = invariantJacobian(q);
  const Jet energy = spring(I), angle = jointCoordinateChart(spec_.revolute, I, I);
  const Eigen::Matrix<double, Eigen::Dynamic, 1, 0, 3, 1> invariantRate = J * qRate;
  const double rate = angle.grad.head(m).dot(invariantRate);
  double dForce = 0.0;
  const double force = dissipativeForce(rate, &dForce);
  const Vec3 forceOnInvariants = energy.grad + force * angle.grad;
  applyForce(forceOnInvariants, q, out);

  // d rate/dq through I (Hessian of the coordinate) and through J (Hessians of I); d rate/dq'
  ConstraintRow dRateDq = (angle.hess.topLeftCorner(m, m) * invariantRate).transpose() * J;
  for (int a = 0; a < m; ++a) dRateDq += angle.grad[a] * (spec_.invariants[a].hessian * qRate).transpose();
  const ConstraintRow dRateDqRate = angle.grad.head(m).transpose() * J;
  auto K = out.tangent();
  const ConstraintVector direction = J.transpose() * angle.grad.head(m);
  K.block(n_, 0, n_, n_) += args.alpha * (J.transpose() * (energy.hess + force * angle.hess).topLeftCorner(m, m) * J +
                                          direction * (dForce * dRateDq)) +
                            args.beta * direction * (dForce * dRateDqRate);
  for (int a = 0; a < m; ++a) K.block(n_, 0, n_, n_) += args.alpha * forceOnInvariants[a] * spec_.invariants[a].hessian;

  const double power = force * rate;
  if (spec_.heatDof < 0) {
    flows.dissipated += power;
    return;
  }
  out.residual()[2 * n_] -= power;
  K.block(2 * n_, 0, 1, n_) -= (dForce * rate + force) * (args.alpha * dRateDq + args.beta * dRateDqRate);
}

}  // namespace mpx
