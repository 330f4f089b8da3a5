// The eem4 stage form of a hyperelastic solid cell (docs/theory.md section 13.8): at each
// quadrature point the energy-consistent stage gradient of W along C(tau) = F(tau)^T F(tau)
// of the stage polynomial,
//   S~_l = S(C_l) + 2 mu C'_l,  mu = [W(C_end) - W(C_0) - sum_j b_j S_j : C'_j / 2] / sum_j b_j C'_j : C'_j,
// so that sum_l b_l S~_l : C'_l / 2 = W(C_end) - W(C_0), and the nodal forces w F_l S~_l dN_a/dX
// at each stage, whose moments vanish (S~ symmetric).
#include "models/fe/solid_element.hpp"

#include "engine/core/stage_gradient.hpp"

namespace mpx {

namespace {
double contract(const Mat3& a, const Mat3& b) { return (a.array() * b.array()).sum(); }
// The change of C = F^T F for a change dF of F.
Mat3 strainChange(const Mat3& F, const Mat3& dF) { return dF.transpose() * F + F.transpose() * dF; }
}  // namespace

Component::StageForm SolidElement::stageForm() const {
  return spec_.branch || spec_.thermal ? StageForm::None : StageForm::Own;
}

void SolidElement::stageLocal(const StageArgs& args, Workspace&, LocalSystem& out, Flows&) const {
  const CollocationRule& rule = *args.rule;
  const int l = args.stage, column = args.column, s = rule.stages, momentumRow = 3 * nodes_;
  const bool own = l == column;
  // node positions at the basis points of the stage polynomial (the start, then each stage)
  NodePositions basis[CollocationRule::kMostStages + 1];
  basis[0] = positions(args.zOld);
  for (int j = 0; j < s; ++j) basis[j + 1] = positions(args.stageState[j]);
  const NodePositions xEnd = positions(args.zEnd);
  auto r = out.residual();
  auto K = out.tangent();
  for (int q = 0; q < static_cast<int>(spec_.points.size()); ++q) {
    const ShapeGradients& G = spec_.points[q].gradients;
    const double w = spec_.points[q].weight;
    // F, its tau-rate and C, C' at each stage; C at the start and the end
    Mat3 F[CollocationRule::kMostStages], rate[CollocationRule::kMostStages], C[CollocationRule::kMostStages],
        strainRate[CollocationRule::kMostStages], stress[CollocationRule::kMostStages];
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
    const double floorRatio = kStagePathFloor / (norm + kStagePathFloor);
    const double dFlooredDNorm = 1.0 - floorRatio * floorRatio;
    norm += kStagePathFloor * floorRatio;
    const double mu = defect / norm;
    const Mat3 consistentStress = stress[l] + 2.0 * mu * strainRate[l];

    // nodal forces w F_l S~_l dN_a/dX
    const Mat3 firstPiola = w * F[l] * consistentStress;
    for (int a = 0; a < nodes_; ++a) r.segment<3>(momentumRow + 3 * a) += firstPiola * G.row(a).transpose();

    // their derivative with respect to stage `column`'s positions: through F_l and S(C_l) on
    // the own stage, and through mu and C'_l (the rates see every stage)
    const Mat3 columnTangent = spec_.material->stressIncrement(C[column], strainRate[column]);
    for (int b = 0; b < nodes_; ++b)
      for (int i = 0; i < 3; ++i) {
        Mat3 dF = Mat3::Zero();
        dF.row(i) = G.row(b);
        double dDefect = rule.end[column + 1] * 0.5 * contract(stressEnd, strainChange(FEnd, dF)), dNorm = 0.0;
        Mat3 dStrainRateOwn = Mat3::Zero();
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
        }
        const double dMu = (dDefect - mu * dFlooredDNorm * dNorm) / norm;
        Mat3 dStress = 2.0 * dMu * strainRate[l] + 2.0 * mu * dStrainRateOwn;
        if (own) dStress += spec_.material->stressIncrement(C[l], strainChange(F[l], dF));
        Mat3 dPiola = w * F[l] * dStress;
        if (own) dPiola += w * dF * consistentStress;
        for (int a = 0; a < nodes_; ++a) K.block<3, 1>(momentumRow + 3 * a, 3 * b + i) += dPiola * G.row(a).transpose();
      }
  }
}

}  // namespace mpx
