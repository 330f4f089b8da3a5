#include "models/lumped/lumped_element.hpp"

#include <cmath>

namespace mpx {

namespace {
constexpr unsigned kStretchBit = 1u, kThermalBit = 2u, kInternalBit = 4u;
}  // namespace

std::vector<int> LumpedElement::collectDofs(const LumpedElementSpec& spec) {
  std::vector<int> dofs;
  if (spec.ends) dofs = TwoPointGeometry(spec.ends->first, spec.ends->second).dofs();
  if (spec.thermalDof >= 0) dofs.push_back(spec.thermalDof);
  if (spec.internalDof >= 0) dofs.push_back(spec.internalDof);
  return dofs;
}

LumpedElement::LumpedElement(LumpedElementSpec spec) : Component(spec.name, collectDofs(spec)), spec_(std::move(spec)) {
  const int n = static_cast<int>(dofs().size());
  if (spec_.ends) {
    geometry_.emplace(spec_.ends->first, spec_.ends->second);
    mask_ |= kStretchBit;
  }
  if (spec_.thermalDof >= 0) {
    mask_ |= kThermalBit;
    localThermal_ = n - 1 - (spec_.internalDof >= 0 ? 1 : 0);
  }
  if (spec_.internalDof >= 0) {
    mask_ |= kInternalBit;
    localInternal_ = n - 1;
  }
}

Vec3 LumpedElement::arguments(const double* z) const {
  return {geometry_ ? geometry_->separation(z).squaredNorm() : 0.0, localThermal_ >= 0 ? z[spec_.thermalDof] : 0.0,
          localInternal_ >= 0 ? z[spec_.internalDof] : 0.0};
}

void LumpedElement::argumentRows(const Vec3& separation, LocalRow (&rows)[3]) const {
  const int n = static_cast<int>(dofs().size());
  for (auto& row : rows) row.setZero(n);
  if (geometry_) geometry_->addSeparationRow(rows[0], 2.0 * separation);
  if (localThermal_ >= 0) rows[1][localThermal_] = 1.0;
  if (localInternal_ >= 0) rows[2][localInternal_] = 1.0;
}

LocalRow LumpedElement::chain(const Vec3& dArguments, const LocalRow (&rows)[3]) {
  return dArguments[0] * rows[0] + dArguments[1] * rows[1] + dArguments[2] * rows[2];
}

LumpedElement::Response LumpedElement::respond(const DiscreteGradient& dEnergy,
                                               const DiscreteGradient& dEntropy) const {
  Response r;
  // discrete temperature: D_s e / D_s eta
  if (mask_ & kThermalBit) {
    r.theta = dEnergy.grad[1] / dEntropy.grad[1];
    r.dTheta = (dEnergy.dGradDb.row(1) - r.theta * dEntropy.dGradDb.row(1)).transpose() / dEntropy.grad[1];
  }
  // conjugate force of c and viscous driving force of gamma, from the free energy
  r.force = dEnergy.grad[0] - r.theta * dEntropy.grad[0];
  r.dForce = (dEnergy.dGradDb.row(0) - r.theta * dEntropy.dGradDb.row(0)).transpose() - dEntropy.grad[0] * r.dTheta;
  r.drivingForce = -(dEnergy.grad[2] - r.theta * dEntropy.grad[2]);
  r.dDrivingForce =
      -(dEnergy.dGradDb.row(2) - r.theta * dEntropy.dGradDb.row(2)).transpose() + dEntropy.grad[2] * r.dTheta;
  // viscosity at the (discrete) temperature
  const Viscosity& v = spec_.viscosity;
  r.viscosity = v.reference;
  if (mask_ & kThermalBit) {
    r.viscosity *= std::exp(-v.activation * (r.theta - v.referenceTemperature));
    r.dViscosity = -v.activation * r.viscosity * r.dTheta;
  }
  return r;
}

void LumpedElement::addBalances(const Response& response, const LocalRow (&rows)[3], double zCoefficient,
                                const Vec3& forceDirection, double gammaRate, double entropyRate, Workspace& ws,
                                LocalSystem& out, Flows& flows) const {
  auto r = out.residual();
  auto K = out.tangent();
  if (geometry_) {
    geometry_->addForce(out, response.force * forceDirection);
    geometry_->addForceTangent(out, forceDirection, zCoefficient * chain(response.dForce, rows));
  }
  const double g = response.drivingForce, nu = response.viscosity;
  const LocalRow dDissipation =
      chain((2.0 * g / nu) * response.dDrivingForce - (g * g / (nu * nu)) * response.dViscosity, rows);
  if (localInternal_ >= 0) {
    r[localInternal_] += nu * gammaRate - g;
    K.row(localInternal_) += zCoefficient * chain(gammaRate * response.dViscosity - response.dDrivingForce, rows);
  }
  if (localThermal_ >= 0) {
    // the viscous power heats the element's own node
    const double heating = localInternal_ >= 0 ? g * g / nu : 0.0;
    r[localThermal_] += response.theta * entropyRate - heating;
    K.row(localThermal_) += zCoefficient * (entropyRate * chain(response.dTheta, rows) -
                                            (localInternal_ >= 0 ? dDissipation : LocalRow::Zero(r.size())));
    NodeTemperature& node = ws.nodes[spec_.thermalNode];
    node.value = response.theta;
    node.count = out.n;
    Eigen::Map<LocalRow>(node.grad, out.n) = zCoefficient * chain(response.dTheta, rows);
  } else if (localInternal_ >= 0) {
    flows.dissipated += g * g / nu;
  }
}

void LumpedElement::eemLocal(const StepArgs& args, Workspace& ws, LocalSystem& out, Flows& flows) const {
  const Vec3 a = arguments(args.zOld), b = arguments(args.zNew);
  auto energy = [&](const Vec3& x) { return spec_.law->energy(x); };
  auto entropy = [&](const Vec3& x) { return spec_.law->entropy(x); };
  const bool gonzalez = spec_.form == DiscreteGradientForm::Gonzalez;
  const DiscreteGradient dEnergy = gonzalez ? gonzalezGradient(energy, mask_, a, b, spec_.argumentScale)
                                            : partitionedGradient(energy, mask_, a, b, spec_.argumentScale);
  const DiscreteGradient dEntropy = gonzalez ? gonzalezGradient(entropy, mask_, a, b, spec_.argumentScale)
                                             : partitionedGradient(entropy, mask_, a, b, spec_.argumentScale);
  const Response response = respond(dEnergy, dEntropy);

  // derivatives of the end-point arguments b with respect to zNew
  LocalRow rows[3];
  Vec3 separationMid = Vec3::Zero();
  if (geometry_) separationMid = 0.5 * (geometry_->separation(args.zOld) + geometry_->separation(args.zNew));
  argumentRows(geometry_ ? geometry_->separation(args.zNew) : Vec3::Zero(), rows);

  const Jet entropyNew = entropy(b);
  const double gammaRate = (b[2] - a[2]) / args.dt;
  const double entropyRate = (entropyNew.value - entropy(a).value) / args.dt;
  addBalances(response, rows, 1.0, 2.0 * separationMid, gammaRate, entropyRate, ws, out, flows);

  // terms from the explicit dependence on zNew: force direction 2 d_mid, gamma' and eta'
  auto K = out.tangent();
  if (geometry_) geometry_->addSeparationTangent(out, response.force * Eigen::Matrix3d::Identity());
  if (localInternal_ >= 0) K(localInternal_, localInternal_) += response.viscosity / args.dt;
  if (localThermal_ >= 0) K.row(localThermal_) += (response.theta / args.dt) * chain(entropyNew.grad, rows);
}

void LumpedElement::rateLocal(const RateArgs& args, Workspace& ws, LocalSystem& out, Flows& flows) const {
  const Vec3 a = arguments(args.z);
  const Jet energy = spec_.law->energy(a);
  const Jet entropy = spec_.law->entropy(a);
  const Response response = respond(exactGradient(energy), exactGradient(entropy));

  LocalRow rows[3];
  const Vec3 separation = geometry_ ? geometry_->separation(args.z) : Vec3::Zero();
  argumentRows(separation, rows);
  // argument rates: c' = 2 d . d', s', gamma'
  const Vec3 separationRate = geometry_ ? geometry_->separationRate(args.zdot) : Vec3::Zero();
  const Vec3 argumentRate(2.0 * separation.dot(separationRate), localThermal_ >= 0 ? args.zdot[spec_.thermalDof] : 0.0,
                          localInternal_ >= 0 ? args.zdot[spec_.internalDof] : 0.0);
  const double entropyRate = entropy.grad.dot(argumentRate);
  addBalances(response, rows, args.alpha, 2.0 * separation, argumentRate[2], entropyRate, ws, out, flows);

  // explicit dependence on z (force direction, c' through d) and on zdot (the rates)
  auto K = out.tangent();
  if (geometry_)
    geometry_->addSeparationTangent(out, (args.alpha * 2.0 * response.force) * Eigen::Matrix3d::Identity());
  if (localInternal_ >= 0) K(localInternal_, localInternal_) += args.beta * response.viscosity;
  if (localThermal_ >= 0) {
    LocalRow dEntropyRate = chain(entropy.hess * argumentRate, rows);
    if (geometry_) geometry_->addSeparationRow(dEntropyRate, 2.0 * entropy.grad[0] * separationRate);
    K.row(localThermal_) += args.alpha * response.theta * dEntropyRate;
    // zdot enters through the argument rates, whose zdot-rows equal the z-rows of the arguments
    K.row(localThermal_) += args.beta * response.theta * chain(entropy.grad, rows);
  }
}

void LumpedElement::measure(const double* z, Measures& out) const {
  const Vec3 a = arguments(z);
  const Jet energy = spec_.law->energy(a);
  const Jet entropy = spec_.law->entropy(a);
  out.energy += energy.value;
  out.entropy += entropy.value;
  if (localThermal_ >= 0) out.nodeTemperature[spec_.thermalNode] = energy.grad[1] / entropy.grad[1];
}

}  // namespace mpx
