#include "models/multibody/external_torque.hpp"

namespace mpx {

namespace {
std::vector<int> directorDofs(int firstDirectorDof, int velocityShift) {
  std::vector<int> dofs;
  for (int i = 0; i < 9; ++i) dofs.push_back(firstDirectorDof + i);
  for (int i = 0; i < 9; ++i) dofs.push_back(firstDirectorDof + velocityShift + i);
  return dofs;
}

Eigen::Matrix3d crossMatrix(const Vec3& a) {
  Eigen::Matrix3d m;
  m << 0.0, -a.z(), a.y(), a.z(), 0.0, -a.x(), -a.y(), a.x(), 0.0;
  return m;
}
}  // namespace

ExternalTorque::ExternalTorque(std::string name, int firstDirectorDof, int velocityShift, const Vec3& torque,
                               TimeFunction profile)
    : Component(std::move(name), directorDofs(firstDirectorDof, velocityShift)),
      firstDirectorDof_(firstDirectorDof),
      velocityShift_(velocityShift),
      torque_(torque),
      profile_(std::move(profile)) {}

void ExternalTorque::measure(const double*, Measures&) const {}

void ExternalTorque::apply(double t, const double* directors, const double* directorRates, double tangentCoefficient,
                           LocalSystem& out, Flows& flows) const {
  const Vec3 torque = profile_(t) * torque_;
  auto r = out.residual();
  auto K = out.tangent();
  for (int i = 0; i < 3; ++i) {
    const Vec3 force = 0.5 * torque.cross(Eigen::Map<const Vec3>(directors + 3 * i));
    r.segment<3>(9 + 3 * i) -= force;
    K.block<3, 3>(9 + 3 * i, 3 * i) -= tangentCoefficient * crossMatrix(torque);
    flows.externalWork += force.dot(Eigen::Map<const Vec3>(directorRates + 3 * i));
  }
}

void ExternalTorque::eemLocal(const StepArgs& args, Workspace&, LocalSystem& out, Flows& flows) const {
  // mid-step directors; their increment over dt is the rate the step's work is done with
  double mid[9], rate[9];
  for (int i = 0; i < 9; ++i) {
    const double before = args.zOld[firstDirectorDof_ + i], after = args.zNew[firstDirectorDof_ + i];
    mid[i] = 0.5 * (before + after);
    rate[i] = (after - before) / args.dt;
  }
  apply(args.t + 0.5 * args.dt, mid, rate, 0.25, out, flows);
}

void ExternalTorque::rateLocal(const RateArgs& args, Workspace&, LocalSystem& out, Flows& flows) const {
  apply(args.t, args.z + firstDirectorDof_, args.z + firstDirectorDof_ + velocityShift_, 0.5 * args.alpha, out, flows);
}

}  // namespace mpx
