// The eem4 stage form of a solid cell (docs/theory.md sections 13.8 and 13.9). At each
// quadrature point each energy takes the energy-consistent stage gradient along the stage
// polynomial: the stored energy W and a thermal cell's coupling entropy L = 3 beta K ln J along
// C(tau) = F(tau)^T F(tau),
//   S~_l = S(C_l) + 2 mu C'_l,  mu = [W(C_end) - W(C_0) - sum_j b_j S_j : C'_j / 2] / sum_j b_j C'_j : C'_j,
// and the Maxwell branch's Psi_v along A(tau) = E(tau) - Gamma(tau),
//   D Psi_l = S_v(A_l) + nu A'_l,  nu = [Psi_v(A_end) - Psi_v(A_0) - sum_j b_j S_v(A_j) : A'_j] / sum_j b_j A'_j :
//   A'_j,
// so that the Gauss sums of the stress power are the energies' changes. The nodal forces are
// w F_l (S~_l + D Psi_l + (theta_R - theta_l) S~L_l) dN_a/dX at each stage, with theta_l the
// point's stage temperature sum_a N_a T_a,l (moments vanish: the stresses are symmetric), and
// the viscous strain follows Gamma' = D Psi_l / eta there, dissipating D Psi_l : D Psi_l / eta.
// A thermal node's heat row at stage l is T_a,l times its entropy balance, as in the EEM step
// with the stage temperature T_a,l (models/fe/nodal_thermal_variable.hpp) for the logarithmic
// mean and S~L_l : C'_l / 2 for the coupling entropy's change.
#include "models/fe/cell_tensors.hpp"
#include "models/fe/solid_element.hpp"

#include "engine/core/stage_gradient.hpp"

#include <cmath>
#include <optional>

namespace mpx {

using cell::branchStressOf;
using cell::contract;
using cell::kComponent;
using cell::strainChangeOfRow;
using cell::SymmetricTangent;

namespace {
constexpr int kStages = CollocationRule::kMostStages;
using CellPositions = Eigen::Matrix<double, 3, kMaxCellNodes>;

// The change of C = F^T F for a change dF of F.
Mat3 strainChange(const Mat3& F, const Mat3& dF) { return dF.transpose() * F + F.transpose() * dF; }

// The floor of the rates' norm (engine/core/stage_gradient.hpp). A solid's defect takes W's
// change from C's change, and that from F's change, so its round-off is eps |S| |C'|, not
// eps |W|, and mu does not amplify it where C barely moves; the floor keeps the tangent's share
// of that round-off (eps / k) small. The lumped elements' 1e-10 left out most of the defect of
// a stiff link in almost rigid motion: the flexible pendulum's balance drifted to 3.6e-6 over
// 6 s with eem4; with this floor 3.2e-10, as with eem.
constexpr double kSolidPathFloor = 1e-14;

// The correction coefficient of a stage gradient from its quadrature defect and the norm of the
// argument's rates, with that floor: (coefficient, the floored norm, d(floored norm)/d(norm)).
struct Correction {
  double coefficient, norm, normSlope;
};
Correction correction(double defect, double norm) {
  const FlooredNorm floored = flooredNorm(norm, kSolidPathFloor);
  return {defect / floored.value, floored.value, floored.slope};
}

// One quadrature point's motion along the stage polynomial: F, its tau-rate F', C and
// C' = F'^T F + F^T F' at each stage, C at the start and the end, and sum_j b_j C'_j : C'_j, the
// norm every energy of C shares.
struct PointPath {
  Mat3 F[kStages], rate[kStages], C[kStages], strainRate[kStages];
  Mat3 FEnd, C0, CEnd;
  Mat3 CChange;  // CEnd - C0 from F's change, free of C's round-off
  double norm = 0.0;
};

// (start: the node positions at the step's start; change[j]: their change to stage j). The
// stage polynomial is linear in the stage values, so are F, its tau-rates and its end value:
// they come from each stage's change of F, and a rate carries the round-off of the changes.
PointPath pointPath(const CellPositions& start, const CellPositions (&change)[kStages], const ShapeGradients& G,
                    const CollocationRule& rule) {
  PointPath path;
  const Mat3 F0 = start * G;
  Mat3 dF[kStages];
  Mat3 FChange = Mat3::Zero();
  for (int j = 0; j < rule.stages; ++j) {
    dF[j] = change[j] * G;
    FChange += rule.end[j + 1] * dF[j];
  }
  path.FEnd = F0 + FChange;
  for (int j = 0; j < rule.stages; ++j) {
    path.F[j] = F0 + dF[j];
    path.rate[j].setZero();
    for (int k = 0; k < rule.stages; ++k) path.rate[j] += rule.rate[j][k + 1] * dF[k];
    path.C[j] = path.F[j].transpose() * path.F[j];
    path.strainRate[j] = strainChange(path.F[j], path.rate[j]);
    path.norm += rule.weight[j] * contract(path.strainRate[j], path.strainRate[j]);
  }
  path.C0 = F0.transpose() * F0;
  path.CChange = strainChange(F0, FChange) + FChange.transpose() * FChange;
  path.CEnd = path.FEnd.transpose() * path.FEnd;
  return path;
}

// What a change dF = e_row g^T of F at stage `column` (one position column: a node's shape
// gradient g in one row) does to the path: each stage's C', C at that stage and at the end
// (with its end coefficient), and the norm. All zero for a column that leaves the positions.
struct PathChange {
  PathChange() {
    for (Mat3& rate : strainRate) rate.setZero();
  }
  Mat3 strainRate[kStages];
  Mat3 ownStrain = Mat3::Zero(), endStrain = Mat3::Zero();
  double norm = 0.0;
};

PathChange pathChange(const PointPath& path, const CollocationRule& rule, int column, int row,
                      const Eigen::RowVector3d& g) {
  PathChange change;
  change.ownStrain = strainChangeOfRow(path.F[column], row, g);
  change.endStrain = rule.end[column + 1] * strainChangeOfRow(path.FEnd, row, g);
  for (int j = 0; j < rule.stages; ++j) {
    change.strainRate[j] = rule.rate[j][column + 1] * strainChangeOfRow(path.F[j], row, g);
    if (j == column) change.strainRate[j] += strainChangeOfRow(path.rate[j], row, g);
    change.norm += 2.0 * rule.weight[j] * contract(path.strainRate[j], change.strainRate[j]);
  }
  return change;
}

// An energy of C along a point's path (W, or the coupling's L) and its stage gradients; with a
// tangent column (the stage whose values the tangent differentiates by, -1 for the residual
// alone), also what change() needs.
class StrainEnergyPath {
 public:
  StrainEnergyPath(const HyperelasticMaterial& law, const PointPath& path, const CollocationRule& rule, int column)
      : path_(path), rule_(rule), column_(column) {
    double defect = law.energyDifference(path.C0, path.CChange);
    for (int j = 0; j < rule.stages; ++j) {
      stress_[j] = law.stress(path.C[j]);
      defect -= rule.weight[j] * 0.5 * contract(stress_[j], path.strainRate[j]);
    }
    correction_ = correction(defect, path.norm);
    for (int j = 0; j < rule.stages; ++j)
      gradient_[j] = stress_[j] + 2.0 * correction_.coefficient * path.strainRate[j];
    if (column < 0) return;
    stressEnd_ = law.stress(path.CEnd);
    tangent_.emplace([&](const Mat3& dC) { return law.stressIncrement(path.C[column], dC); });
    columnTangent_ = (*tangent_)(path.strainRate[column]);
  }
  const Mat3& gradient(int stage) const { return gradient_[stage]; }

  // The change of S~_l at stage l: through mu (every stage's C', C_end and the column stage's
  // stress) and, on the column's own stage, through S(C_l). In mu's derivative the material
  // tangent enters only as dS(C_k)[C'_k] (its major symmetry: dS_k[dC_k] : C'_k = dC_k : dS_k[C'_k]).
  Mat3 change(const PathChange& d, int stage) const {
    double dDefect = 0.5 * contract(stressEnd_, d.endStrain);
    for (int j = 0; j < rule_.stages; ++j) {
      double dPower = contract(stress_[j], d.strainRate[j]);
      if (j == column_) dPower += contract(d.ownStrain, columnTangent_);
      dDefect -= rule_.weight[j] * 0.5 * dPower;
    }
    const double dMu = (dDefect - correction_.coefficient * correction_.normSlope * d.norm) / correction_.norm;
    Mat3 dGradient = 2.0 * dMu * path_.strainRate[stage] + 2.0 * correction_.coefficient * d.strainRate[stage];
    if (stage == column_) dGradient += (*tangent_)(d.ownStrain);
    return dGradient;
  }

 private:
  const PointPath& path_;
  const CollocationRule& rule_;
  int column_;
  Mat3 stress_[kStages], gradient_[kStages], stressEnd_, columnTangent_;
  std::optional<SymmetricTangent> tangent_;  // dS at the column stage's C
  Correction correction_{};
};

// The Maxwell branch's energy along A = E - Gamma and its stage gradients D Psi_l.
class BranchPath {
 public:
  // (gamma: the viscous strain at the start and at each stage; gammaRate: its tau-rates; column
  // as for StrainEnergyPath)
  BranchPath(const ViscousBranch& branch, const PointPath& path, const Mat3 (&gamma)[kStages + 1],
             const Mat3 (&gammaRate)[kStages], const Mat3& gammaEnd, const CollocationRule& rule, int column)
      : branch_(branch), rule_(rule), column_(column) {
    const Mat3 A0 = greenStrain(path.C0) - gamma[0], AEnd = greenStrain(path.CEnd) - gammaEnd;
    stressEnd_ = branchStressOf(branch, AEnd);
    // Psi_v is quadratic in A: its change is exact from the mean stress, and A's change comes from
    // C's change (not AEnd - A0), so that its round-off is in proportion to the motion
    const Mat3 AChange = 0.5 * path.CChange - (gammaEnd - gamma[0]);
    double defect = 0.5 * contract(AChange, branchStressOf(branch, AEnd + A0)), norm = 0.0;
    for (int j = 0; j < rule.stages; ++j) {
      A_[j] = greenStrain(path.C[j]) - gamma[j + 1];
      rate_[j] = 0.5 * path.strainRate[j] - gammaRate[j];
      stress_[j] = branchStressOf(branch, A_[j]);
      defect -= rule.weight[j] * contract(stress_[j], rate_[j]);
      norm += rule.weight[j] * contract(rate_[j], rate_[j]);
    }
    correction_ = correction(defect, norm);
    for (int j = 0; j < rule.stages; ++j) gradient_[j] = stress_[j] + correction_.coefficient * rate_[j];
  }
  const Mat3& gradient(int stage) const { return gradient_[stage]; }

  // The change of D Psi_l at stage l for a change d of the positions' path and dGamma of the
  // column stage's viscous strain (S_v is linear and symmetric: S_v(dA_j) : A'_j = dA_j : S_v(A'_j)).
  Mat3 change(const PathChange& d, const Mat3& dGamma, int stage) const {
    double dDefect = contract(stressEnd_, 0.5 * d.endStrain - rule_.end[column_ + 1] * dGamma), dNorm = 0.0;
    Mat3 dRateOwn = Mat3::Zero();
    const Mat3 dAOwn = 0.5 * d.ownStrain - dGamma;
    for (int j = 0; j < rule_.stages; ++j) {
      const Mat3 dRate = 0.5 * d.strainRate[j] - rule_.rate[j][column_ + 1] * dGamma;
      double dPower = contract(stress_[j], dRate);
      if (j == column_) dPower += contract(dAOwn, branchStressOf(branch_, rate_[j]));
      dDefect -= rule_.weight[j] * dPower;
      dNorm += 2.0 * rule_.weight[j] * contract(rate_[j], dRate);
      if (j == stage) dRateOwn = dRate;
    }
    const double dNu = (dDefect - correction_.coefficient * correction_.normSlope * dNorm) / correction_.norm;
    Mat3 dGradient = dNu * rate_[stage] + correction_.coefficient * dRateOwn;
    if (stage == column_) dGradient += branchStressOf(branch_, dAOwn);
    return dGradient;
  }

 private:
  const ViscousBranch& branch_;
  const CollocationRule& rule_;
  int column_;
  Mat3 A_[kStages], rate_[kStages], stress_[kStages], gradient_[kStages], stressEnd_;
  Correction correction_{};
};
}  // namespace

// A quadrature point's path through the stages and its energies' stage gradients (the
// coupling's in a thermal cell, the branch's in a viscous one).
struct SolidElement::StagePoint {
  int q;
  const PointPath& path;
  const StrainEnergyPath& elastic;
  const StrainEnergyPath* coupling;
  const BranchPath* branch;
};

void SolidElement::addStagePoint(const StageArgs& args, int l, const StagePoint& point,
                                 const NodalThermalVariable::Stage* node, LocalSystem& out, Flows& flows) const {
  const CollocationRule& rule = *args.rule;
  const int q = point.q, column = args.column, momentumRow = 3 * nodes_, gammaRow = 6 * nodes_ + 6 * q;
  const CellPoint& p = spec_.points[q];
  const ShapeGradients& G = p.gradients;
  const double w = p.weight;
  const PointPath& path = point.path;
  const StrainEnergyPath& elastic = point.elastic;
  const StrainEnergyPath* coupling = point.coupling;
  const BranchPath* branch = point.branch;
  auto r = out.residual();
  auto K = out.tangent();
  Mat3 totalStress = elastic.gradient(l);

  // a thermal point: its stage temperature and the coupling's stage gradient, whose power is
  // the rate of the coupling entropy
  double temperature = 0.0, shift = 0.0, entropyRate = 0.0;
  ShapeValues temperatureSlope = ShapeValues::Zero();
  if (coupling) {
    for (int a = 0; a < nodes_; ++a) {
      temperature += p.values[a] * node[a].temperature.value;
      temperatureSlope[a] = p.values[a] * node[a].temperature.slope;
    }
    shift = spec_.thermal->referenceTemperature - temperature;
    totalStress += shift * coupling->gradient(l);
    entropyRate = 0.5 * contract(coupling->gradient(l), path.strainRate[l]) / args.dt;
  }

  // the branch: Gamma' = D Psi_l / eta at the stage; its dissipation leaves a mechanical cell
  // and heats a thermal cell's nodes
  const Fluidity fluidity = fluidityAt(temperature);
  double heating = 0.0;
  if (branch) {
    const Mat3& branchStress = branch->gradient(l);
    totalStress += branchStress;
    for (int k = 0; k < 6; ++k) {
      const auto [i, j] = kComponent[k];
      r[gammaRow + k] = args.stageRate[l][spec_.firstInternalDof + 6 * q + k] - fluidity.value * branchStress(i, j);
    }
    heating = w * fluidity.value * contract(branchStress, branchStress);
    if (!coupling) flows.dissipated += heating;
  }

  // nodal forces w F_l (S~_l + D Psi_l + shift S~L_l) dN_a/dX; heat rows T_a,l w N_a L' - N_a heating
  const Mat3 firstPiola = w * path.F[l] * totalStress;
  for (int a = 0; a < nodes_; ++a) r.segment<3>(momentumRow + 3 * a) += firstPiola * G.row(a).transpose();
  if (coupling)
    for (int a = 0; a < nodes_; ++a)
      r[firstThermal_ + a] += node[a].temperature.value * w * p.values[a] * entropyRate - p.values[a] * heating;
  if (!args.tangent) return;

  // A position or viscous-strain column of stage `column`: the positions move row `row` of F
  // by g (the path by d; row -1: they stay), the viscous strain by dGamma.
  auto addColumn = [&](int localColumn, int row, const Eigen::RowVector3d& g, const PathChange& d, const Mat3& dGamma) {
    const bool moves = row >= 0;
    Mat3 dStress = moves ? elastic.change(d, l) : Mat3::Zero();
    Mat3 dBranch = Mat3::Zero();
    if (branch) {
      dBranch = branch->change(d, dGamma, l);
      dStress += dBranch;
      for (int k = 0; k < 6; ++k)
        K(gammaRow + k, localColumn) -= fluidity.value * dBranch(kComponent[k][0], kComponent[k][1]);
    }
    if (coupling) {
      const Mat3 dCoupling = moves ? coupling->change(d, l) : Mat3::Zero();
      dStress += shift * dCoupling;
      const double dEntropyRate =
          0.5 * (contract(dCoupling, path.strainRate[l]) + contract(coupling->gradient(l), d.strainRate[l])) / args.dt;
      const double dHeating = branch ? 2.0 * w * fluidity.value * contract(branch->gradient(l), dBranch) : 0.0;
      for (int a = 0; a < nodes_; ++a)
        K(firstThermal_ + a, localColumn) +=
            node[a].temperature.value * w * p.values[a] * dEntropyRate - p.values[a] * dHeating;
    }
    Mat3 dPiola = w * path.F[l] * dStress;
    if (l == column && moves) dPiola.row(row) += w * g * totalStress;
    for (int a = 0; a < nodes_; ++a) K.block<3, 1>(momentumRow + 3 * a, localColumn) += dPiola * G.row(a).transpose();
  };
  for (int b = 0; b < nodes_; ++b)
    for (int i = 0; i < 3; ++i)
      addColumn(3 * b + i, i, G.row(b), pathChange(path, rule, column, i, G.row(b)), Mat3::Zero());
  if (branch)
    for (int m = 0; m < 6; ++m) {
      Mat3 dGamma = Mat3::Zero();
      dGamma(kComponent[m][0], kComponent[m][1]) = dGamma(kComponent[m][1], kComponent[m][0]) = 1.0;
      addColumn(gammaRow + m, -1, Eigen::RowVector3d::Zero(), PathChange{}, dGamma);
      // the viscous strain's own rate
      K(gammaRow + m, gammaRow + m) += rule.rate[l][column + 1] / args.dt;
    }
  if (!coupling) return;

  // A temperature column of stage `column`: T_b,l moves the point's temperature, and with it
  // the coupling stress, the fluidity and the heating, and weights node b's row.
  for (int b = 0; b < nodes_; ++b) {
    const int thermalColumn = firstThermal_ + b;
    const double dTemperature = temperatureSlope[b];
    const Mat3 dPiola = -dTemperature * w * path.F[l] * coupling->gradient(l);
    for (int a = 0; a < nodes_; ++a) K.block<3, 1>(momentumRow + 3 * a, thermalColumn) += dPiola * G.row(a).transpose();
    K(thermalColumn, thermalColumn) += node[b].temperature.slope * w * p.values[b] * entropyRate;
    if (!branch) continue;
    const double dFluidity = fluidity.slope * dTemperature;
    for (int k = 0; k < 6; ++k)
      K(gammaRow + k, thermalColumn) -= dFluidity * branch->gradient(l)(kComponent[k][0], kComponent[k][1]);
    const double dHeating = w * dFluidity * contract(branch->gradient(l), branch->gradient(l));
    for (int a = 0; a < nodes_; ++a) K(firstThermal_ + a, thermalColumn) -= p.values[a] * dHeating;
  }
}

void SolidElement::stageLocal(const StageArgs& args, Workspace&, LocalSystem& out, Flows& flows) const {
  addStages(args, args.stage, 1, &out, &flows);
}

void SolidElement::stageResiduals(const StageArgs& args, Workspace&, LocalSystem* out, Flows* flows) const {
  addStages(args, 0, args.rule->stages, out, flows);
}

void SolidElement::addStages(const StageArgs& args, int firstStage, int count, LocalSystem* out, Flows* flows) const {
  const CollocationRule& rule = *args.rule;
  const int s = rule.stages, column = args.tangent ? args.column : -1;
  auto reject = [&] {
    for (int k = 0; k < count; ++k) rejectInadmissible(out[k]);
  };
  // node positions at the step's start and their change to each stage
  const CellPositions start = positions(args.zOld);
  CellPositions change[kStages];
  for (int j = 0; j < s; ++j) change[j] = positions(args.stageState[j]) - start;
  // a thermal cell's nodes at each stage: T_a,l, the capacity's energy rate, their derivatives
  NodalThermalVariable::Stage node[kStages][kMaxCellNodes];
  if (spec_.thermal)
    for (int k = 0; k < count; ++k) {
      StageArgs atStage = args;
      atStage.stage = firstStage + k;
      if (!args.tangent) atStage.column = atStage.stage;
      for (int a = 0; a < nodes_; ++a) {
        node[k][a] = spec_.thermalVariable.stage(atStage, spec_.thermalDofs[a]);
        const double T = node[k][a].temperature.value;
        if (!(std::isfinite(T) && T > 0.0)) return reject();
      }
    }
  for (int q = 0; q < static_cast<int>(spec_.points.size()); ++q) {
    // the point's path through all stages, and its energies' stage gradients, serve every stage
    const PointPath path = pointPath(start, change, spec_.points[q].gradients, rule);
    if (!(path.FEnd.determinant() > 0.0)) return reject();
    for (int k = 0; k < count; ++k)
      if (!(path.F[firstStage + k].determinant() > 0.0)) return reject();
    const StrainEnergyPath elastic(*spec_.material, path, rule, column);
    std::optional<StrainEnergyPath> coupling;
    if (spec_.thermal) coupling.emplace(*coupling_, path, rule, column);
    std::optional<BranchPath> branch;
    if (spec_.branch) {
      Mat3 gamma[kStages + 1], gammaRate[kStages];
      gamma[0] = viscousStrain(args.zOld, q);
      for (int j = 0; j < s; ++j) {
        gamma[j + 1] = viscousStrain(args.stageState[j], q);
        gammaRate[j] = args.dt * viscousStrain(args.stageRate[j], q);
      }
      branch.emplace(*spec_.branch, path, gamma, gammaRate, viscousStrain(args.zEnd, q), rule, column);
    }
    const StagePoint point{q, path, elastic, coupling ? &*coupling : nullptr, branch ? &*branch : nullptr};
    for (int k = 0; k < count; ++k) addStagePoint(args, firstStage + k, point, node[k], out[k], flows[k]);
  }
  // the heat capacity, lumped at the nodes: m_a D_s e s'_l
  if (!spec_.thermal) return;
  for (int k = 0; k < count; ++k) {
    ShapeValues rates = ShapeValues::Zero(), slopes = ShapeValues::Zero();
    for (int a = 0; a < nodes_; ++a) {
      rates[a] = node[k][a].energyRate.value;
      slopes[a] = node[k][a].energyRate.slope;
    }
    addHeatCapacity(rates, slopes, out[k]);
  }
}

}  // namespace mpx
