#include "models/fe/solid_element.hpp"

#include "models/fe/cell_tensors.hpp"
#include "models/fe/discrete_stress.hpp"

#include "engine/core/discrete_gradient.hpp"

#include <cmath>
#include <limits>
#include <optional>

namespace mpx {

using cell::branchStressOf;
using cell::contract;
using cell::kComponent;
using cell::strainChangeOfRow;
using cell::SymmetricTangent;

namespace {
std::vector<int> collectDofs(const SolidElementSpec& spec) {
  std::vector<int> dofs;
  for (int shift : {0, spec.velocityShift})
    for (int first : spec.positionDofs)
      for (int k = 0; k < 3; ++k) dofs.push_back(first + shift + k);
  if (spec.branch)
    for (std::size_t k = 0; k < 6 * spec.points.size(); ++k)
      dofs.push_back(spec.firstInternalDof + static_cast<int>(k));
  if (spec.thermal) dofs.insert(dofs.end(), spec.thermalDofs.begin(), spec.thermalDofs.end());
  return dofs;
}

}  // namespace

// A quadrature point as one scheme sees it. EEM: forces at F_m with the discrete stress,
// derivatives with respect to the end point (dF_m/dx' = 1/2, dE_m/dC' = 1/4, dGamma_m/dGamma'
// = 1/2). Rate form: everything at z, tangent alpha d/dz + beta d/dzdot.
struct SolidElement::PointEvaluation {
  Mat3 forceGradient;          // F the forces act with
  double forceGradientFactor;  // its derivative with respect to the end positions
  Mat3 endGradient;            // F of the end positions the tangent differentiates
  Mat3 stress;                 // total second Piola-Kirchhoff stress
  Mat3 branchStress = Mat3::Zero();
  double strainFactor = 0.0, gammaFactor = 0.0;  // dE/dC_end and dGamma/dGamma_end of the branch's argument
  Mat3 gammaRate = Mat3::Zero();                 // (Gamma' - Gamma)/dt or dGamma/dt
  double gammaRateCoefficient = 0.0;             // its derivative: 1/dt or beta
  double tangentScale = 1.0;                     // 1 or alpha
  // thermal cells: the point's temperature theta = sum_a N_a T_a, its derivative with respect
  // to each node's thermal dof, the coupling stress per unit (theta_R - theta) and the rate
  // of the coupling entropy 3 beta K ln J
  double temperature = 0.0;
  ShapeValues temperatureSlope = ShapeValues::Zero();
  Mat3 couplingStress = Mat3::Zero();
  double entropyRate = 0.0;
  // the branch's fluidity 1/eta at the point's temperature and its derivative in that temperature
  double fluidity = 0.0, fluiditySlope = 0.0;
};

// The nodal temperatures T_a the heat rows are weighted with and their derivatives dT_a/ds_a in
// the nodes' thermal dofs s_a (unscaled: the rate form applies alpha through tangentScale).
struct SolidElement::NodeTemperatures {
  ShapeValues value = ShapeValues::Zero();
  ShapeValues slope = ShapeValues::Zero();
};

SolidElement::SolidElement(SolidElementSpec spec)
    : Component(spec.name, collectDofs(spec)),
      spec_(std::move(spec)),
      nodes_(static_cast<int>(spec_.positionDofs.size())),
      firstThermal_(6 * nodes_ + (spec_.branch ? 6 * static_cast<int>(spec_.points.size()) : 0)) {
  nodeVolume_.setZero();
  for (const CellPoint& p : spec_.points) nodeVolume_ += p.weight * p.values;
  if (spec_.thermal) coupling_.emplace(spec_.thermal->couplingModulus());
}

// Without a thermal field the branch's dissipation leaves the system; with one it heats the
// cell's nodes instead (assembleHeat).
void SolidElement::addDissipation(int q, const PointEvaluation& e, Flows& flows) const {
  if (!spec_.thermal)
    flows.dissipated += spec_.points[q].weight * contract(e.branchStress, e.branchStress) / spec_.branch->viscosity;
}

void SolidElement::addHeatCapacity(const ShapeValues& energyRates, const ShapeValues& energyRateSlopes,
                                   LocalSystem& out) const {
  for (int a = 0; a < nodes_; ++a) {
    const int row = firstThermal_ + a;
    out.r[row] += nodeVolume_[a] * energyRates[a];
    out.tangent()(row, row) += nodeVolume_[a] * energyRateSlopes[a];
  }
}

ShapeValues SolidElement::nodeTemperatures(const double* z) const {
  ShapeValues theta = ShapeValues::Zero();
  for (int a = 0; a < nodes_; ++a) theta[a] = spec_.thermalVariable.temperature(z[spec_.thermalDofs[a]]);
  return theta;
}

// eta(theta) = eta_R exp(-a (theta - theta_R)) at a point's temperature (constant without a
// thermal field)
SolidElement::Fluidity SolidElement::fluidityAt(double temperature) const {
  if (!spec_.branch) return {};
  const double fluidity = 1.0 / spec_.branch->viscosity;
  if (!spec_.thermal) return {fluidity, 0.0};
  const double activation = spec_.thermal->viscosityActivation;
  const double value = fluidity * std::exp(activation * (temperature - spec_.thermal->referenceTemperature));
  return {value, activation * value};
}

void SolidElement::setFluidity(PointEvaluation& e) const {
  const Fluidity f = fluidityAt(e.temperature);
  e.fluidity = f.value;
  e.fluiditySlope = f.slope;
}

double SolidElement::pointTemperature(int q, const NodeTemperatures& nodes) const {
  return spec_.points[q].values.dot(nodes.value);
}

SolidElement::NodePositions SolidElement::positions(const double* z) const {
  NodePositions x = NodePositions::Zero();
  for (int a = 0; a < nodes_; ++a) x.col(a) = Eigen::Map<const Vec3>(z + spec_.positionDofs[a]);
  return x;
}

Mat3 SolidElement::viscousStrain(const double* z, int point) const {
  const double* g = z + spec_.firstInternalDof + 6 * point;
  Mat3 gamma;
  gamma << g[0], g[3], g[5], g[3], g[1], g[4], g[5], g[4], g[2];
  return gamma;
}

bool SolidElement::couples(int row, int column, LocalForm) const {
  enum class Kind { Position, Velocity, Strain, Thermal };
  auto kind = [&](int local) {
    if (local < 3 * nodes_) return Kind::Position;
    if (local < 6 * nodes_) return Kind::Velocity;
    return local < firstThermal_ ? Kind::Strain : Kind::Thermal;
  };
  const bool expands = spec_.thermal && spec_.thermal->expansion != 0.0;
  const bool activated = spec_.thermal && spec_.thermal->viscosityActivation != 0.0;
  const Kind columnKind = kind(column);
  switch (kind(row)) {
    case Kind::Velocity:
      return columnKind == Kind::Position || columnKind == Kind::Strain || (columnKind == Kind::Thermal && expands);
    case Kind::Strain:
      return columnKind == Kind::Position || (columnKind == Kind::Thermal && activated) ||
             (columnKind == Kind::Strain && (row - 6 * nodes_) / 6 == (column - 6 * nodes_) / 6);
    case Kind::Thermal:
      return columnKind == Kind::Thermal || columnKind == Kind::Strain ||
             (columnKind == Kind::Position && (expands || spec_.branch));
    case Kind::Position:
      break;
  }
  return false;  // the kinematic rows are the inertia's
}

void SolidElement::measure(const double* z, Measures& out) const {
  const NodePositions x = positions(z);
  for (std::size_t q = 0; q < spec_.points.size(); ++q) {
    const Mat3 F = x * spec_.points[q].gradients, C = F.transpose() * F;
    double energy = spec_.material->energy(C);
    if (spec_.branch) energy += spec_.branch->energy(C, viscousStrain(z, static_cast<int>(q)));
    if (coupling_) {
      const double couplingEntropy = coupling_->energy(C);
      energy += spec_.thermal->referenceTemperature * couplingEntropy;
      out.entropy += spec_.points[q].weight * couplingEntropy;
    }
    out.energy += spec_.points[q].weight * energy;
  }
  if (!spec_.thermal) return;
  // the heat capacity, lumped at the nodes
  for (int a = 0; a < nodes_; ++a) {
    const double s = z[spec_.thermalDofs[a]];
    out.energy += nodeVolume_[a] * spec_.thermalVariable.energy(s);
    out.entropy += nodeVolume_[a] * spec_.thermalVariable.entropy(s);
  }
}

// A cell turned inside out (det F <= 0) is no admissible state, although C = F^T F, and with it
// every energy, looks regular there: a non-finite residual makes Newton backtrack or the step
// fail, instead of the run going on in a mirrored configuration.
void SolidElement::rejectInadmissible(LocalSystem& out) { out.r[0] = std::numeric_limits<double>::quiet_NaN(); }

template <class MaterialIncrement>
void SolidElement::assemblePoint(int q, const PointEvaluation& e, const MaterialIncrement& materialIncrement,
                                 LocalSystem& out) const {
  auto r = out.residual();
  auto K = out.tangent();
  const ShapeGradients& G = spec_.points[q].gradients;
  const double w = spec_.points[q].weight, s = e.tangentScale;
  const int momentumRow = 3 * nodes_, gammaRow = 6 * nodes_ + 6 * q;
  const double fluidity = e.fluidity;

  // nodal forces w F S dN_a/dX, and the branch's evolution rows
  const Mat3 firstPiola = w * e.forceGradient * e.stress;
  for (int a = 0; a < nodes_; ++a) r.segment<3>(momentumRow + 3 * a) += firstPiola * G.row(a).transpose();
  if (spec_.branch)
    for (int k = 0; k < 6; ++k) {
      const auto [i, j] = kComponent[k];
      r[gammaRow + k] = e.gammaRate(i, j) - fluidity * e.branchStress(i, j);
    }
  // a residual-only evaluation, of a rate or an EEM step (every tangent term below carries s or
  // gammaRateCoefficient)
  if (s == 0.0 && e.gammaRateCoefficient == 0.0) return;

  // a thermal cell's nodes are heated by the branch: d(S_v:S_v/eta) = 2 S_v:dS_v/eta
  auto addHeatingColumn = [&](int column, const Mat3& dBranch) {
    if (!spec_.thermal) return;
    const double dHeating = 2.0 * w * fluidity * contract(e.branchStress, dBranch);
    for (int a = 0; a < nodes_; ++a) K(firstThermal_ + a, column) -= s * spec_.points[q].values[a] * dHeating;
  };

  // columns of the end positions: dF = e_j dN_b/dX^T changes C by dF^T F + F^T dF
  const SymmetricTangent tangent(materialIncrement);
  for (int b = 0; b < nodes_; ++b)
    for (int j = 0; j < 3; ++j) {
      Mat3 dF = Mat3::Zero();
      dF.row(j) = G.row(b);
      const Mat3 dC = strainChangeOfRow(e.endGradient, j, G.row(b));
      Mat3 dStress = tangent(dC);
      if (spec_.branch) {
        const Mat3 dBranch = branchStressOf(*spec_.branch, e.strainFactor * dC);
        dStress += dBranch;
        for (int k = 0; k < 6; ++k)
          K(gammaRow + k, 3 * b + j) -= s * fluidity * dBranch(kComponent[k][0], kComponent[k][1]);
        addHeatingColumn(3 * b + j, dBranch);
      }
      const Mat3 dPiola = w * (e.forceGradientFactor * dF * e.stress + e.forceGradient * dStress);
      for (int a = 0; a < nodes_; ++a)
        K.block<3, 1>(momentumRow + 3 * a, 3 * b + j) += s * dPiola * G.row(a).transpose();
    }

  // columns of the temperatures: the coupling stress changes by -dtheta S_L, the branch's
  // flow and heating by dfluidity
  if (spec_.thermal) {
    const Mat3 dPiola = -w * e.forceGradient * e.couplingStress;
    const double heatingPerFluidity = w * contract(e.branchStress, e.branchStress);
    for (int b = 0; b < nodes_; ++b) {
      const double dFluidity = s * e.fluiditySlope * e.temperatureSlope[b];
      for (int a = 0; a < nodes_; ++a) {
        K.block<3, 1>(momentumRow + 3 * a, firstThermal_ + b) +=
            s * e.temperatureSlope[b] * dPiola * G.row(a).transpose();
        K(firstThermal_ + a, firstThermal_ + b) -= spec_.points[q].values[a] * heatingPerFluidity * dFluidity;
      }
      if (spec_.branch)
        for (int k = 0; k < 6; ++k)
          K(gammaRow + k, firstThermal_ + b) -= dFluidity * e.branchStress(kComponent[k][0], kComponent[k][1]);
    }
  }
  if (!spec_.branch) return;

  // columns of the viscous strain (a unit symmetric tensor per component)
  for (int m = 0; m < 6; ++m) {
    Mat3 dGamma = Mat3::Zero();
    dGamma(kComponent[m][0], kComponent[m][1]) = dGamma(kComponent[m][1], kComponent[m][0]) = 1.0;
    const Mat3 dBranch = branchStressOf(*spec_.branch, -e.gammaFactor * dGamma);
    const Mat3 dPiola = w * e.forceGradient * dBranch;
    for (int a = 0; a < nodes_; ++a)
      K.block<3, 1>(momentumRow + 3 * a, gammaRow + m) += s * dPiola * G.row(a).transpose();
    for (int k = 0; k < 6; ++k)
      K(gammaRow + k, gammaRow + m) -= s * fluidity * dBranch(kComponent[k][0], kComponent[k][1]);
    K(gammaRow + m, gammaRow + m) += e.gammaRateCoefficient;
    addHeatingColumn(gammaRow + m, dBranch);
  }
}

void SolidElement::assembleHeat(int q, const PointEvaluation& e, const Mat3& entropyRateGradient,
                                const NodeTemperatures& nodes, LocalSystem& out) const {
  auto r = out.residual();
  auto K = out.tangent();
  const CellPoint& p = spec_.points[q];
  const double heating = p.weight * contract(e.branchStress, e.branchStress) * e.fluidity;
  for (int a = 0; a < nodes_; ++a) {
    const int row = firstThermal_ + a;
    const double share = p.weight * p.values[a];
    r[row] += nodes.value[a] * share * e.entropyRate - p.values[a] * heating;
    K(row, row) += e.tangentScale * nodes.slope[a] * share * e.entropyRate;
    for (int b = 0; b < nodes_; ++b)
      K.block<1, 3>(row, 3 * b) += nodes.value[a] * share * p.gradients.row(b) * entropyRateGradient;
  }
}

void SolidElement::eemLocal(const StepArgs& args, Workspace&, LocalSystem& out, Flows& flows) const {
  const NodePositions x0 = positions(args.zOld), x1 = positions(args.zNew);
  NodeTemperatures nodes;
  if (spec_.thermal)
    for (int a = 0; a < nodes_; ++a) {
      const int dof = spec_.thermalDofs[a];
      const TemperatureJet T = spec_.thermalVariable.step(args.zOld[dof], args.zNew[dof]);
      nodes.value[a] = T.value;
      nodes.slope[a] = T.slope;
    }
  for (int q = 0; q < static_cast<int>(spec_.points.size()); ++q) {
    const ShapeGradients& G = spec_.points[q].gradients;
    const Mat3 F0 = x0 * G, F1 = x1 * G;
    if (!(F1.determinant() > 0.0)) return rejectInadmissible(out);
    const Mat3 C0 = F0.transpose() * F0, C1 = F1.transpose() * F1;
    const DiscreteStress discrete(*spec_.material, C0, C1, args.tangent);
    PointEvaluation e{0.5 * (F0 + F1), 0.5, F1, discrete.stress()};
    e.strainFactor = 0.25;
    e.gammaFactor = 0.5;
    e.gammaRateCoefficient = 1.0 / args.dt;
    // residual only: assemblePoint stops after the residual rows
    if (!args.tangent) e.tangentScale = e.gammaRateCoefficient = 0.0;
    if (spec_.branch) {
      const Mat3 gamma0 = viscousStrain(args.zOld, q), gamma1 = viscousStrain(args.zNew, q);
      e.branchStress = spec_.branch->stress(0.5 * (C0 + C1), 0.5 * (gamma0 + gamma1));
      e.stress += e.branchStress;
      e.gammaRate = (gamma1 - gamma0) / args.dt;
      addDissipation(q, e, flows);
    }
    // the coupling stress acts at the point's discrete temperature, with the Gonzalez stress of
    // 3 beta K ln J; the coupling entropy's change is exact
    std::optional<DiscreteStress> coupling;
    double couplingShift = 0.0;
    Mat3 entropyRateGradient = Mat3::Zero();
    if (spec_.thermal) {
      coupling.emplace(*coupling_, C0, C1, args.tangent);
      e.temperature = pointTemperature(q, nodes);
      e.temperatureSlope = spec_.points[q].values.cwiseProduct(nodes.slope);
      e.couplingStress = coupling->stress();
      couplingShift = spec_.thermal->referenceTemperature - e.temperature;
      e.stress += couplingShift * e.couplingStress;
      e.entropyRate = coupling_->energyDifference(C0, C1 - C0) / args.dt;
      entropyRateGradient = spec_.thermal->couplingModulus() / args.dt * F1.inverse();
    }
    setFluidity(e);
    assemblePoint(
        q, e,
        [&](const Mat3& dC) {
          Mat3 dStress = discrete.increment(dC);
          if (coupling) dStress += couplingShift * coupling->increment(dC);
          return dStress;
        },
        out);
    if (spec_.thermal) assembleHeat(q, e, entropyRateGradient, nodes, out);
  }
  // the heat capacity: m_a kappa (theta_a' - theta_a) = T_a m_a kappa ln(theta_a'/theta_a)
  if (spec_.thermal) {
    ShapeValues rates = ShapeValues::Zero(), slopes = ShapeValues::Zero();
    for (int a = 0; a < nodes_; ++a) {
      const double s0 = args.zOld[spec_.thermalDofs[a]], s1 = args.zNew[spec_.thermalDofs[a]];
      rates[a] = (spec_.thermalVariable.energy(s1) - spec_.thermalVariable.energy(s0)) / args.dt;
      slopes[a] = spec_.thermalVariable.energySlope(s1) / args.dt;
    }
    addHeatCapacity(rates, slopes, out);
  }
}

void SolidElement::rateLocal(const RateArgs& args, Workspace&, LocalSystem& out, Flows& flows) const {
  // position rates only feed a thermal cell's coupling entropy rate
  const NodePositions x = positions(args.z), xRate = spec_.thermal ? positions(args.zdot) : NodePositions::Zero();
  NodeTemperatures nodes;
  if (spec_.thermal)
    for (int a = 0; a < nodes_; ++a) {
      const TemperatureJet T = spec_.thermalVariable.rate(args.z[spec_.thermalDofs[a]], 1.0);
      nodes.value[a] = T.value;
      nodes.slope[a] = T.slope;
    }
  for (int q = 0; q < static_cast<int>(spec_.points.size()); ++q) {
    const Mat3 F = x * spec_.points[q].gradients, C = F.transpose() * F;
    if (!(F.determinant() > 0.0)) return rejectInadmissible(out);
    PointEvaluation e{F, 1.0, F, spec_.material->stress(C)};
    e.strainFactor = 0.5;
    e.gammaFactor = 1.0;
    e.gammaRateCoefficient = args.beta;
    e.tangentScale = args.alpha;
    if (spec_.branch) {
      e.branchStress = spec_.branch->stress(C, viscousStrain(args.z, q));
      e.stress += e.branchStress;
      e.gammaRate = viscousStrain(args.zdot, q);
      addDissipation(q, e, flows);
    }
    // coupling stress at theta_h; the coupling entropy's rate 3 beta K tr(F^-1 dF/dt)
    double couplingShift = 0.0;
    Mat3 entropyRateGradient = Mat3::Zero();
    if (spec_.thermal) {
      const double modulus = spec_.thermal->couplingModulus();
      const Mat3 inverse = F.inverse(), rate = xRate * spec_.points[q].gradients;
      e.temperature = pointTemperature(q, nodes);
      e.temperatureSlope = spec_.points[q].values.cwiseProduct(nodes.slope);
      e.couplingStress = coupling_->stress(C);
      couplingShift = spec_.thermal->referenceTemperature - e.temperature;
      e.stress += couplingShift * e.couplingStress;
      e.entropyRate = modulus * (inverse * rate).trace();
      entropyRateGradient = modulus * (args.beta * inverse - args.alpha * inverse * rate * inverse);
    }
    setFluidity(e);
    assemblePoint(
        q, e,
        [&](const Mat3& dC) {
          Mat3 dStress = spec_.material->stressIncrement(C, dC);
          if (coupling_) dStress += couplingShift * coupling_->stressIncrement(C, dC);
          return dStress;
        },
        out);
    if (spec_.thermal) assembleHeat(q, e, entropyRateGradient, nodes, out);
  }
  // the heat capacity's energy rate e'(s) ds/dt
  if (spec_.thermal) {
    ShapeValues rates = ShapeValues::Zero(), slopes = ShapeValues::Zero();
    for (int a = 0; a < nodes_; ++a) {
      const double s = args.z[spec_.thermalDofs[a]], sRate = args.zdot[spec_.thermalDofs[a]];
      const NodalThermalVariable& v = spec_.thermalVariable;
      rates[a] = v.energySlope(s) * sRate;
      slopes[a] = args.alpha * v.energyCurvature(s) * sRate + args.beta * v.energySlope(s);
    }
    addHeatCapacity(rates, slopes, out);
  }
}

Mat3 SolidElement::meanCauchyStress(const double* z) const {
  const NodePositions x = positions(z);
  Mat3 sum = Mat3::Zero();
  for (std::size_t q = 0; q < spec_.points.size(); ++q) {
    const Mat3 F = x * spec_.points[q].gradients, C = F.transpose() * F;
    Mat3 S = spec_.material->stress(C);
    if (spec_.branch) S += spec_.branch->stress(C, viscousStrain(z, static_cast<int>(q)));
    sum += F * S * F.transpose() / F.determinant();
  }
  return sum / static_cast<double>(spec_.points.size());
}

Mat3 SolidElement::meanViscousStrain(const double* z) const {
  Mat3 sum = Mat3::Zero();
  if (!spec_.branch) return sum;
  for (std::size_t q = 0; q < spec_.points.size(); ++q) sum += viscousStrain(z, static_cast<int>(q));
  return sum / static_cast<double>(spec_.points.size());
}

Vec3 SolidElement::meanHeatFlux(const double* z) const {
  Vec3 sum = Vec3::Zero();
  if (!spec_.thermal) return sum;
  const ShapeValues theta = nodeTemperatures(z);
  for (const CellPoint& p : spec_.points) sum -= spec_.thermal->conductivity * p.gradients.transpose() * theta;
  return sum / static_cast<double>(spec_.points.size());
}

double SolidElement::meanTemperature(const double* z) const {
  double sum = 0.0;
  if (!spec_.thermal) return sum;
  const ShapeValues theta = nodeTemperatures(z);
  for (const CellPoint& p : spec_.points) sum += p.values.dot(theta);
  return sum / static_cast<double>(spec_.points.size());
}

}  // namespace mpx
