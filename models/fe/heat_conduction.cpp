#include "models/fe/heat_conduction.hpp"

namespace mpx {

HeatConduction::HeatConduction(std::string name, std::vector<int> thermalDofs, NodalThermalVariable thermalVariable,
                               std::vector<CellPoint> points, double conductivity)
    : Component(std::move(name), std::move(thermalDofs)),
      thermalVariable_(thermalVariable),
      points_(std::move(points)),
      conductivity_(conductivity),
      nodes_(static_cast<int>(dofs().size())) {}

void HeatConduction::assemble(const ShapeValues& T, const ShapeValues& slope, LocalSystem& out) const {
  auto r = out.residual();
  auto K = out.tangent();
  for (const CellPoint& p : points_) {
    const ShapeValues& N = p.values;
    const ShapeGradients& G = p.gradients;
    const double theta = N.dot(T);
    const Vec3 gradient = G.transpose() * T, flux = -conductivity_ * gradient;
    const double fluxPower = gradient.dot(flux);  // g . Q
    // h_a = Grad N_a . Q / theta - N_a (g . Q) / theta^2, the row is -w T_a h_a
    for (int a = 0; a < nodes_; ++a) {
      const double h = G.row(a).dot(flux) / theta - N[a] * fluxPower / (theta * theta);
      r[a] -= p.weight * T[a] * h;
      K(a, a) -= p.weight * slope[a] * h;
      for (int b = 0; b < nodes_; ++b) {
        // dh_a/dT_b, with dQ/dT_b = -k0 Grad N_b and d(g . Q)/dT_b = 2 Grad N_b . Q
        const double dh =
            -conductivity_ * G.row(a).dot(G.row(b)) / theta - G.row(a).dot(flux) * N[b] / (theta * theta) -
            N[a] * (2.0 * G.row(b).dot(flux) / (theta * theta) - 2.0 * fluxPower * N[b] / (theta * theta * theta));
        K(a, b) -= p.weight * T[a] * dh * slope[b];
      }
    }
  }
}

void HeatConduction::eemLocal(const StepArgs& args, Workspace&, LocalSystem& out, Flows&) const {
  ShapeValues T = ShapeValues::Zero(), slope = ShapeValues::Zero();
  for (int a = 0; a < nodes_; ++a) {
    const TemperatureJet jet = thermalVariable_.step(args.zOld[dofs()[a]], args.zNew[dofs()[a]]);
    T[a] = jet.value;
    slope[a] = jet.slope;
  }
  assemble(T, slope, out);
}

void HeatConduction::rateLocal(const RateArgs& args, Workspace&, LocalSystem& out, Flows&) const {
  ShapeValues T = ShapeValues::Zero(), slope = ShapeValues::Zero();
  for (int a = 0; a < nodes_; ++a) {
    const TemperatureJet jet = thermalVariable_.rate(args.z[dofs()[a]], args.alpha);
    T[a] = jet.value;
    slope[a] = jet.slope;
  }
  assemble(T, slope, out);
}

void HeatConduction::stageLocal(const StageArgs& args, Workspace&, LocalSystem& out, Flows&) const {
  ShapeValues T = ShapeValues::Zero(), slope = ShapeValues::Zero();
  for (int a = 0; a < nodes_; ++a) {
    const TemperatureJet jet = thermalVariable_.stage(args, dofs()[a]).temperature;
    T[a] = jet.value;
    slope[a] = jet.slope;
  }
  assemble(T, slope, out);
}

}  // namespace mpx
