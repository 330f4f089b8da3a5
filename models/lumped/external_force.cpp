#include "models/lumped/external_force.hpp"

namespace mpx {

ExternalForce::ExternalForce(std::string name, int positionDof, int velocityDof, const Vec3& force,
                             TimeFunction profile)
    : Component(std::move(name), {velocityDof, velocityDof + 1, velocityDof + 2}),
      positionDof_(positionDof),
      velocityDof_(velocityDof),
      force_(force),
      profile_(std::move(profile)) {}

void ExternalForce::measure(const double*, Measures&) const {}

void ExternalForce::apply(double t, const Vec3& velocity, LocalSystem& out, Flows& flows) const {
  const Vec3 force = profile_(t) * force_;
  out.residual() -= force;
  flows.externalWork += force.dot(velocity);
}

void ExternalForce::eemLocal(const StepArgs& args, Workspace&, LocalSystem& out, Flows& flows) const {
  // the position increment over dt is the mean velocity the step's work is done with
  const double* x0 = args.zOld + positionDof_;
  const double* x1 = args.zNew + positionDof_;
  const Vec3 meanVelocity = Vec3(x1[0] - x0[0], x1[1] - x0[1], x1[2] - x0[2]) / args.dt;
  apply(args.t + 0.5 * args.dt, meanVelocity, out, flows);
}

void ExternalForce::rateLocal(const RateArgs& args, Workspace&, LocalSystem& out, Flows& flows) const {
  const double* v = args.z + velocityDof_;
  apply(args.t, Vec3(v[0], v[1], v[2]), out, flows);
}

}  // namespace mpx
