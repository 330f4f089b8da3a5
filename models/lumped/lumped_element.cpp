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
  linearEntropy_ = spec_.law->linearEntropy();
}

Vec3 LumpedElement::separation(const double* z) const { return geometry_ ? geometry_->separation(z) : Vec3::Zero(); }

Vec3 LumpedElement::arguments(const double* z, const Vec3& separation) const {
  return {separation.squaredNorm(), localThermal_ >= 0 ? z[spec_.thermalDof] : 0.0,
          localInternal_ >= 0 ? z[spec_.internalDof] : 0.0};
}

void LumpedElement::argumentRows(const Vec3& separation, LocalRow (&rows)[3], bool tangent) const {
  const int n = tangent ? static_cast<int>(dofs().size()) : 0;
  for (auto& row : rows) row.setZero(n);
  if (!tangent) return;
  if (geometry_) geometry_->addSeparationRow(rows[0], 2.0 * separation);
  if (localThermal_ >= 0) rows[1][localThermal_] = 1.0;
  if (localInternal_ >= 0) rows[2][localInternal_] = 1.0;
}

LocalRow LumpedElement::chain(const Vec3& dArguments, const LocalRow (&rows)[3]) {
  return dArguments[0] * rows[0] + dArguments[1] * rows[1] + dArguments[2] * rows[2];
}

GradientRows LumpedElement::alongRows(const DiscreteGradient& gradient, const LocalRow (&rows)[3]) {
  GradientRows out;
  out.grad = gradient.grad;
  for (int i = 0; i < 3; ++i) out.d[i] = chain(gradient.dGradDb.row(i).transpose(), rows);
  return out;
}

LumpedElement::Response LumpedElement::respond(const GradientRows& dEnergy, const GradientRows& dEntropy) const {
  const int n = static_cast<int>(dEnergy.d[0].size());
  Response r;
  r.dTheta = r.dViscosity = LocalRow::Zero(n);
  // discrete temperature: D_s e / D_s eta
  if (mask_ & kThermalBit) {
    r.theta = dEnergy.grad[1] / dEntropy.grad[1];
    r.dTheta = (dEnergy.d[1] - r.theta * dEntropy.d[1]) / dEntropy.grad[1];
  }
  // conjugate force of c and viscous driving force of gamma, from the free energy
  r.force = dEnergy.grad[0] - r.theta * dEntropy.grad[0];
  r.dForce = dEnergy.d[0] - r.theta * dEntropy.d[0] - dEntropy.grad[0] * r.dTheta;
  r.drivingForce = -(dEnergy.grad[2] - r.theta * dEntropy.grad[2]);
  r.dDrivingForce = -(dEnergy.d[2] - r.theta * dEntropy.d[2]) + dEntropy.grad[2] * r.dTheta;
  // viscosity at the (discrete) temperature, which only an internal variable's flow uses
  const Viscosity& v = spec_.viscosity;
  r.viscosity = v.reference;
  if ((mask_ & kThermalBit) && (mask_ & kInternalBit)) {
    r.viscosity *= std::exp(-v.activation * (r.theta - v.referenceTemperature));
    r.dViscosity = -v.activation * r.viscosity * r.dTheta;
  }
  return r;
}

void LumpedElement::addBalances(const Response& response, double zCoefficient, const Vec3& forceDirection,
                                double gammaRate, double entropyRate, Workspace& ws, LocalSystem& out,
                                Flows& flows) const {
  auto r = out.residual();
  auto K = out.tangent();
  // a response without derivatives (a residual-only evaluation) adds no tangent terms
  const bool tangent = response.dTheta.size() > 0;
  const double g = response.drivingForce, nu = response.viscosity;
  if (geometry_) geometry_->addForce(out, response.force * forceDirection);
  if (localInternal_ >= 0) r[localInternal_] += nu * gammaRate - g;
  if (localThermal_ >= 0) {
    // the viscous power heats the element's own node
    const double heating = localInternal_ >= 0 ? g * g / nu : 0.0;
    r[localThermal_] += response.theta * entropyRate - heating;
    NodeTemperature& node = ws.nodes[spec_.thermalNode];
    node.value = response.theta;
    node.count = tangent ? out.n : 0;
  } else if (localInternal_ >= 0) {
    flows.dissipated += g * g / nu;
  }
  if (!tangent) return;

  if (geometry_) geometry_->addForceTangent(out, forceDirection, zCoefficient * response.dForce);
  if (localInternal_ >= 0)
    K.row(localInternal_) += zCoefficient * (gammaRate * response.dViscosity - response.dDrivingForce);
  if (localThermal_ >= 0) {
    // theta times the entropy rate, less the viscous heating g^2/nu where an internal variable flows
    if (localInternal_ >= 0) {
      const LocalRow dDissipation = (2.0 * g / nu) * response.dDrivingForce - (g * g / (nu * nu)) * response.dViscosity;
      K.row(localThermal_) += zCoefficient * (entropyRate * response.dTheta - dDissipation);
    } else {
      K.row(localThermal_) += zCoefficient * (entropyRate * response.dTheta);
    }
    Eigen::Map<LocalRow>(ws.nodes[spec_.thermalNode].grad, out.n) = zCoefficient * response.dTheta;
  }
}

void LumpedElement::eemLocal(const StepArgs& args, Workspace& ws, LocalSystem& out, Flows& flows) const {
  const Vec3 separationOld = separation(args.zOld), separationNew = separation(args.zNew);
  const Vec3 a = arguments(args.zOld, separationOld), b = arguments(args.zNew, separationNew);
  auto energy = [&](const Vec3& x) { return spec_.law->energy(x); };
  auto entropy = [&](const Vec3& x) { return spec_.law->entropy(x); };
  const bool gonzalez = spec_.form == DiscreteGradientForm::Gonzalez;
  auto discreteGradient = [&](const auto& f) {
    return gonzalez ? gonzalezGradient(f, mask_, a, b, spec_.argumentScale)
                    : partitionedGradient(f, mask_, a, b, spec_.argumentScale);
  };
  const Jet entropyNew = entropy(b);
  const DiscreteGradient dEnergy = discreteGradient(energy);
  const DiscreteGradient dEntropy = linearEntropy_ ? exactGradient(entropyNew) : discreteGradient(entropy);

  // derivatives of the end-point arguments b with respect to zNew
  LocalRow rows[3];
  const Vec3 separationMid = 0.5 * (separationOld + separationNew);
  argumentRows(separationNew, rows, args.tangent);
  const Response response = respond(alongRows(dEnergy, rows), alongRows(dEntropy, rows));

  const double gammaRate = (b[2] - a[2]) / args.dt;
  const double entropyRate = (entropyNew.value - entropy(a).value) / args.dt;
  addBalances(response, 1.0, 2.0 * separationMid, gammaRate, entropyRate, ws, out, flows);
  if (!args.tangent) return;

  // terms from the explicit dependence on zNew: force direction 2 d_mid, gamma' and eta'
  auto K = out.tangent();
  if (geometry_) geometry_->addSeparationTangent(out, response.force * Eigen::Matrix3d::Identity());
  if (localInternal_ >= 0) K(localInternal_, localInternal_) += response.viscosity / args.dt;
  if (localThermal_ >= 0) K.row(localThermal_) += (response.theta / args.dt) * chain(entropyNew.grad, rows);
}

void LumpedElement::rateLocal(const RateArgs& args, Workspace& ws, LocalSystem& out, Flows& flows) const {
  const Vec3 separation = this->separation(args.z);
  const Vec3 a = arguments(args.z, separation);
  const Jet energy = spec_.law->energy(a);
  const Jet entropy = spec_.law->entropy(a);

  LocalRow rows[3];
  const bool tangent = args.alpha != 0.0 || args.beta != 0.0;
  argumentRows(separation, rows, tangent);
  const Response response = respond(alongRows(exactGradient(energy), rows), alongRows(exactGradient(entropy), rows));
  // argument rates: c' = 2 d . d', s', gamma'
  const Vec3 separationRate = geometry_ ? geometry_->separationRate(args.zdot) : Vec3::Zero();
  const Vec3 argumentRate(2.0 * separation.dot(separationRate), localThermal_ >= 0 ? args.zdot[spec_.thermalDof] : 0.0,
                          localInternal_ >= 0 ? args.zdot[spec_.internalDof] : 0.0);
  const double entropyRate = entropy.grad.dot(argumentRate);
  addBalances(response, args.alpha, 2.0 * separation, argumentRate[2], entropyRate, ws, out, flows);
  if (!tangent) return;

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

void LumpedElement::fillStageData(const StageArgs& args, StageData& data) const {
  const CollocationRule& rule = *args.rule;
  StagePath& path = data.path;
  const Vec3 separationEnd = separation(args.zEnd);
  path.start = arguments(args.zOld, separation(args.zOld));
  path.end = arguments(args.zEnd, separationEnd);
  argumentRows(separationEnd, path.endRows, args.tangent);
  for (int j = 0; j < rule.stages; ++j) {
    const double* z = args.stageState[j];
    const double* zdot = args.stageRate[j];
    const Vec3& separation = data.separation[j] = this->separation(z);
    const Vec3& separationRate = data.separationRate[j] = geometry_ ? geometry_->separationRate(zdot) : Vec3::Zero();
    path.value[j] = arguments(z, separation);
    // tau-rates a' = dt (2 d . d', s', gamma')
    path.rate[j] =
        args.dt * Vec3(2.0 * separation.dot(separationRate), localThermal_ >= 0 ? zdot[spec_.thermalDof] : 0.0,
                       localInternal_ >= 0 ? zdot[spec_.internalDof] : 0.0);
    argumentRows(separation, path.rows[j], args.tangent);
  }
  auto energy = [&](const Vec3& x) { return spec_.law->energy(x); };
  auto entropy = [&](const Vec3& x) { return spec_.law->entropy(x); };
  data.energy = stageJets(energy, mask_, spec_.argumentScale, rule, path);
  if (linearEntropy_)
    data.entropy.end = entropy(path.end);
  else
    data.entropy = stageJets(entropy, mask_, spec_.argumentScale, rule, path);
}

void LumpedElement::columnRows(const StageArgs& args, StageData& data) const {
  const CollocationRule& rule = *args.rule;
  StagePath& path = data.path;
  path.column = args.column;
  // a'_j depends on stage k's values through the rates (coefficient rule.rate) and, for c,
  // on its own stage's separation as well (rows as empty as path.rows without a tangent)
  for (int j = 0; j < rule.stages; ++j) {
    const double rateCoefficient = rule.rate[j][args.column + 1];
    for (int i = 0; i < 3; ++i) path.rateRows[j][i] = rateCoefficient * path.rows[j][i];
    if (args.tangent && geometry_ && j == args.column)
      geometry_->addSeparationRow(path.rateRows[j][0], 2.0 * args.dt * data.separationRate[j]);
  }
}

void LumpedElement::stageLocal(const StageArgs& args, Workspace& ws, LocalSystem& out, Flows& flows) const {
  // the path and the jets once per evaluation where the workspace keeps them between passes
  if (auto* kept = static_cast<StageData*>(stageScratch(ws))) {
    if (!args.samePath) fillStageData(args, *kept);
    stageBalances(args, *kept, ws, out, flows);
    return;
  }
  StageData own;
  fillStageData(args, own);
  stageBalances(args, own, ws, out, flows);
}

void LumpedElement::stageBalances(const StageArgs& args, StageData& data, Workspace& ws, LocalSystem& out,
                                  Flows& flows) const {
  const int l = args.stage;
  columnRows(args, data);
  const StagePath& path = data.path;
  const GradientRows dEnergy = consistentGradient(data.energy, *args.rule, path, l);
  // a linear entropy's stage gradient is its gradient (zero Hessian: zero rows)
  const GradientRows dEntropy = linearEntropy_ ? alongRows(exactGradient(data.entropy.end), path.endRows)
                                               : consistentGradient(data.entropy, *args.rule, path, l);
  Response response = respond(dEnergy, dEntropy);
  // at steps far too long for the motion the stage temperature can leave (0, inf): that is no
  // solution (its heat would lower the entropy), so the residual is made non-finite and Newton
  // backtracks or the step is cut back
  if ((mask_ & kThermalBit) && !(response.theta > 0.0)) response.theta = NAN;

  // rates at the stage: gamma' and the consistent entropy rate D eta . a' / dt, whose Gauss sum
  // is the element's entropy change
  const Vec3& rate = path.rate[l];
  const double gammaRate = rate[2] / args.dt;
  const double entropyRate = dEntropy.grad.dot(rate) / args.dt;
  addBalances(response, 1.0, 2.0 * data.separation[l], gammaRate, entropyRate, ws, out, flows);
  if (!args.tangent) return;

  // explicit dependence: the force direction 2 d_l on its own stage, gamma' and the entropy rate
  auto K = out.tangent();
  if (geometry_ && l == args.column)
    geometry_->addSeparationTangent(out, (2.0 * response.force) * Eigen::Matrix3d::Identity());
  if (localInternal_ >= 0) K.row(localInternal_) += (response.viscosity / args.dt) * path.rateRows[l][2];
  if (localThermal_ >= 0) {
    LocalRow dEntropyRate = chain(dEntropy.grad, path.rateRows[l]);
    for (int i = 0; i < 3; ++i) dEntropyRate += rate[i] * dEntropy.d[i];
    K.row(localThermal_) += (response.theta / args.dt) * dEntropyRate;
  }
}

void LumpedElement::measure(const double* z, Measures& out) const {
  const Vec3 a = arguments(z, separation(z));
  const Jet energy = spec_.law->energy(a);
  const Jet entropy = spec_.law->entropy(a);
  out.energy += energy.value;
  out.entropy += entropy.value;
  if (localThermal_ >= 0) out.nodeTemperature[spec_.thermalNode] = energy.grad[1] / entropy.grad[1];
}

}  // namespace mpx
