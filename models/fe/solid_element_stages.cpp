// The eem4 stage form of a hyperelastic or viscoelastic solid cell (docs/theory.md section
// 13.8). At each quadrature point each energy takes the energy-consistent stage gradient along
// the stage polynomial: the stored energy W along C(tau) = F(tau)^T F(tau),
//   S~_l = S(C_l) + 2 mu C'_l,  mu = [W(C_end) - W(C_0) - sum_j b_j S_j : C'_j / 2] / sum_j b_j C'_j : C'_j,
// and the Maxwell branch's Psi_v along A(tau) = E(tau) - Gamma(tau),
//   D Psi_l = S_v(A_l) + nu A'_l,  nu = [Psi_v(A_end) - Psi_v(A_0) - sum_j b_j S_v(A_j) : A'_j] / sum_j b_j A'_j :
//   A'_j,
// so that the Gauss sums of the stress power are the energies' changes. The nodal forces are
// w F_l (S~_l + D Psi_l) dN_a/dX at each stage (moments vanish: the stresses are symmetric), and
// the viscous strain follows Gamma' = D Psi_l / eta there, dissipating D Psi_l : D Psi_l / eta.
#include "models/fe/cell_tensors.hpp"
#include "models/fe/solid_element.hpp"

#include "engine/core/stage_gradient.hpp"

namespace mpx {

using cell::branchStressOf;
using cell::contract;
using cell::kComponent;

namespace {
// The change of C = F^T F for a change dF of F.
Mat3 strainChange(const Mat3& F, const Mat3& dF) { return dF.transpose() * F + F.transpose() * dF; }

// The correction coefficient of a stage gradient from its quadrature defect and the norm of the
// argument's rates, with the floor of engine/core/stage_gradient.hpp: (coefficient, the floored
// norm, d(floored norm)/d(norm)).
struct Correction {
  double coefficient, norm, normSlope;
};
Correction correction(double defect, double norm) {
  const FlooredNorm floored = flooredNorm(norm);
  return {defect / floored.value, floored.value, floored.slope};
}
}  // namespace

Component::StageForm SolidElement::stageForm() const { return spec_.thermal ? StageForm::None : StageForm::Own; }

void SolidElement::stageLocal(const StageArgs& args, Workspace&, LocalSystem& out, Flows& flows) const {
  const CollocationRule& rule = *args.rule;
  const int l = args.stage, column = args.column, s = rule.stages, momentumRow = 3 * nodes_;
  const bool own = l == column;
  constexpr int kStages = CollocationRule::kMostStages;
  // node positions at the basis points of the stage polynomial (the start, then each stage)
  NodePositions basis[kStages + 1];
  basis[0] = positions(args.zOld);
  for (int j = 0; j < s; ++j) basis[j + 1] = positions(args.stageState[j]);
  const NodePositions xEnd = positions(args.zEnd);
  auto r = out.residual();
  auto K = out.tangent();
  for (int q = 0; q < static_cast<int>(spec_.points.size()); ++q) {
    const ShapeGradients& G = spec_.points[q].gradients;
    const double w = spec_.points[q].weight;
    // F, its tau-rate and C, C' at each stage; C at the start and the end
    Mat3 F[kStages], rate[kStages], C[kStages], strainRate[kStages], stress[kStages];
    for (int j = 0; j < s; ++j) {
      F[j] = basis[j + 1] * G;
      NodePositions xRate = NodePositions::Zero();
      for (int i = 0; i <= s; ++i) xRate += rule.rate[j][i] * basis[i];
      rate[j] = xRate * G;
      C[j] = F[j].transpose() * F[j];
      strainRate[j] = strainChange(F[j], rate[j]);
      stress[j] = spec_.material->stress(C[j]);
    }
    const Mat3 F0 = basis[0] * G, FEnd = xEnd * G;
    if (!(F[l].determinant() > 0.0) || !(FEnd.determinant() > 0.0)) return rejectInverted(out);
    const Mat3 C0 = F0.transpose() * F0, CEnd = FEnd.transpose() * FEnd, stressEnd = spec_.material->stress(CEnd);
    double defect = spec_.material->energyDifference(C0, CEnd), norm = 0.0;
    for (int j = 0; j < s; ++j) {
      defect -= rule.weight[j] * 0.5 * contract(stress[j], strainRate[j]);
      norm += rule.weight[j] * contract(strainRate[j], strainRate[j]);
    }
    const Correction elastic = correction(defect, norm);
    Mat3 totalStress = stress[l] + 2.0 * elastic.coefficient * strainRate[l];
    const Mat3 columnTangent = spec_.material->stressIncrement(C[column], strainRate[column]);

    // the branch: A = E - Gamma at each stage, its tau-rate, and its stage gradient D Psi_l
    Mat3 A[kStages], ARate[kStages], branch[kStages], AEnd = Mat3::Zero(), branchEnd = Mat3::Zero();
    Correction viscous{0.0, 1.0, 0.0};
    Mat3 branchGradient = Mat3::Zero();
    const int gammaRow = 6 * nodes_ + 6 * q;
    if (spec_.branch) {
      auto branchStress = [&](const Mat3& a) { return branchStressOf(*spec_.branch, a); };
      Mat3 gamma[kStages + 1];
      gamma[0] = viscousStrain(args.zOld, q);
      for (int j = 0; j < s; ++j) gamma[j + 1] = viscousStrain(args.stageState[j], q);
      const Mat3 A0 = greenStrain(C0) - gamma[0];
      AEnd = greenStrain(CEnd) - viscousStrain(args.zEnd, q);
      branchEnd = branchStress(AEnd);
      // Psi_v is quadratic in A: its change is exact from the mean stress
      double branchDefect = 0.5 * contract(AEnd - A0, branchStress(AEnd + A0)), branchNorm = 0.0;
      for (int j = 0; j < s; ++j) {
        Mat3 gammaRate = Mat3::Zero();
        for (int i = 0; i <= s; ++i) gammaRate += rule.rate[j][i] * gamma[i];
        A[j] = greenStrain(C[j]) - gamma[j + 1];
        ARate[j] = 0.5 * strainRate[j] - gammaRate;
        branch[j] = branchStress(A[j]);
        branchDefect -= rule.weight[j] * contract(branch[j], ARate[j]);
        branchNorm += rule.weight[j] * contract(ARate[j], ARate[j]);
      }
      viscous = correction(branchDefect, branchNorm);
      branchGradient = branch[l] + viscous.coefficient * ARate[l];
      totalStress += branchGradient;
      // Gamma' = D Psi_l / eta at the stage
      const double fluidity = 1.0 / spec_.branch->viscosity;
      for (int k = 0; k < 6; ++k) {
        const auto [i, j] = kComponent[k];
        r[gammaRow + k] = args.stageRate[l][spec_.firstInternalDof + 6 * q + k] - fluidity * branchGradient(i, j);
      }
      flows.dissipated += w * fluidity * contract(branchGradient, branchGradient);
    }

    // nodal forces w F_l (S~_l + D Psi_l) dN_a/dX
    const Mat3 firstPiola = w * F[l] * totalStress;
    for (int a = 0; a < nodes_; ++a) r.segment<3>(momentumRow + 3 * a) += firstPiola * G.row(a).transpose();

    // A column of stage `column`: its positions move F by dF, its viscous strain by dGamma.
    // The stresses change through F_l and S(C_l), A_l on the own stage, and through the
    // corrections and the rates, which see every stage.
    auto addColumn = [&](int localColumn, const Mat3& dF, const Mat3& dGamma) {
      double dDefect = rule.end[column + 1] * 0.5 * contract(stressEnd, strainChange(FEnd, dF)), dNorm = 0.0;
      Mat3 dStrainRateOwn = Mat3::Zero();
      double dBranchDefect = 0.0, dBranchNorm = 0.0;
      Mat3 dARateOwn = Mat3::Zero();
      if (spec_.branch)
        dBranchDefect = rule.end[column + 1] * contract(branchEnd, 0.5 * strainChange(FEnd, dF) - dGamma);
      for (int j = 0; j < s; ++j) {
        // C'_j = F'_j^T F_j + F_j^T F'_j: F'_j moves with rule.rate, F_j on its own stage
        Mat3 dStrainRate = strainChange(F[j], rule.rate[j][column + 1] * dF);
        if (j == column) dStrainRate += strainChange(rate[j], dF);
        // dS_j[dC_j] : C'_j = dC_j : dS_j[C'_j] (the tangent's major symmetry)
        double dPower = contract(stress[j], dStrainRate);
        if (j == column) dPower += contract(strainChange(F[j], dF), columnTangent);
        dDefect -= rule.weight[j] * 0.5 * dPower;
        dNorm += 2.0 * rule.weight[j] * contract(strainRate[j], dStrainRate);
        if (j == l) dStrainRateOwn = dStrainRate;
        if (!spec_.branch) continue;
        const Mat3 dARate = 0.5 * dStrainRate - rule.rate[j][column + 1] * dGamma;
        // S_v is linear and symmetric: S_v(dA_j) : A'_j = dA_j : S_v(A'_j)
        double dBranchPower = contract(branch[j], dARate);
        if (j == column) {
          const Mat3 dA = 0.5 * strainChange(F[j], dF) - dGamma;
          dBranchPower += contract(dA, branchStressOf(*spec_.branch, ARate[j]));
        }
        dBranchDefect -= rule.weight[j] * dBranchPower;
        dBranchNorm += 2.0 * rule.weight[j] * contract(ARate[j], dARate);
        if (j == l) dARateOwn = dARate;
      }
      const double dMu = (dDefect - elastic.coefficient * elastic.normSlope * dNorm) / elastic.norm;
      Mat3 dStress = 2.0 * dMu * strainRate[l] + 2.0 * elastic.coefficient * dStrainRateOwn;
      // (a viscous-strain column leaves C, so the material increment is only taken for positions)
      if (own && localColumn < momentumRow) dStress += spec_.material->stressIncrement(C[l], strainChange(F[l], dF));
      if (spec_.branch) {
        const double dNu = (dBranchDefect - viscous.coefficient * viscous.normSlope * dBranchNorm) / viscous.norm;
        Mat3 dBranch = dNu * ARate[l] + viscous.coefficient * dARateOwn;
        if (own) {
          const Mat3 dA = 0.5 * strainChange(F[l], dF) - dGamma;
          dBranch += branchStressOf(*spec_.branch, dA);
        }
        dStress += dBranch;
        const double fluidity = 1.0 / spec_.branch->viscosity;
        for (int k = 0; k < 6; ++k)
          K(gammaRow + k, localColumn) -= fluidity * dBranch(kComponent[k][0], kComponent[k][1]);
      }
      Mat3 dPiola = w * F[l] * dStress;
      if (own) dPiola += w * dF * totalStress;
      for (int a = 0; a < nodes_; ++a) K.block<3, 1>(momentumRow + 3 * a, localColumn) += dPiola * G.row(a).transpose();
    };
    for (int b = 0; b < nodes_; ++b)
      for (int i = 0; i < 3; ++i) {
        Mat3 dF = Mat3::Zero();
        dF.row(i) = G.row(b);
        addColumn(3 * b + i, dF, Mat3::Zero());
      }
    if (!spec_.branch) continue;
    for (int m = 0; m < 6; ++m) {
      Mat3 dGamma = Mat3::Zero();
      dGamma(kComponent[m][0], kComponent[m][1]) = dGamma(kComponent[m][1], kComponent[m][0]) = 1.0;
      addColumn(gammaRow + m, Mat3::Zero(), dGamma);
      // the viscous strain's own rate
      K(gammaRow + m, gammaRow + m) += rule.rate[l][column + 1] / args.dt;
    }
  }
}

}  // namespace mpx
