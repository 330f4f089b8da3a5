#include "tools/output/solid_frames.hpp"

#include "tools/output/surface_picture.hpp"

#include <fmt/format.h>

namespace mpx {

namespace {
// The six independent components xx, yy, zz, xy, yz, xz of a symmetric tensor.
void appendSymmetric(const Mat3& t, std::vector<double>& out) {
  out.insert(out.end(), {t(0, 0), t(1, 1), t(2, 2), t(0, 1), t(1, 2), t(0, 2)});
}

double vonMisesOf(const Mat3& sigma) {
  const Mat3 deviator = sigma - sigma.trace() / 3 * Mat3::Identity();
  return std::sqrt(1.5 * (deviator.array() * deviator.array()).sum());
}
}  // namespace

SolidFrames::SolidFrames(const std::filesystem::path& directory, const CompiledScene& scene, double interval)
    : directory_(directory), interval_(interval), schedule_(interval) {
  for (const SolidPlacement& solid : scene.solids) {
    std::filesystem::create_directories(directory / solid.name);
    series_.push_back({&solid, PvdSeries((directory / (solid.name + ".pvd")).string()), {}, {}});
  }
}

void SolidFrames::write(const StepRecord& record) {
  if (series_.empty()) return;
  if (!schedule_.due(record.time)) return;
  // frames are numbered by output time from t = 0, so a restart does not overwrite the first ones
  frame_ = frame_ >= 0       ? frame_ + 1
           : interval_ > 0.0 ? static_cast<int>(std::floor(record.time / interval_ - 1e-9)) + 1
                             : record.step;
  const double* z = record.state->data();
  for (Series& s : series_) {
    const SolidPlacement& solid = *s.solid;
    const Mesh& mesh = *solid.mesh;
    VtkField displacement{"displacement", 3, {}}, velocity{"velocity", 3, {}};
    s.positions.resize(mesh.nodes.size());
    for (std::size_t n = 0; n < mesh.nodes.size(); ++n) {
      const int dof = solid.firstPositionDof + 3 * static_cast<int>(n);
      s.positions[n] = Eigen::Map<const Vec3>(z + dof);
      const Vec3 u = s.positions[n] - mesh.nodes[n];
      displacement.values.insert(displacement.values.end(), {u.x(), u.y(), u.z()});
      velocity.values.insert(velocity.values.end(), {z[dof + solid.velocityShift], z[dof + solid.velocityShift + 1],
                                                     z[dof + solid.velocityShift + 2]});
    }
    std::vector<VtkField> nodeFields = {displacement, velocity};
    const bool thermal = !solid.thermalDofs.empty();
    if (thermal) {
      VtkField temperature{"temperature", 1, {}};
      for (std::size_t n = 0; n < solid.thermalDofs.size(); ++n)
        temperature.values.push_back(solid.nodeTemperature(z, static_cast<int>(n)));
      nodeFields.push_back(std::move(temperature));
    }
    VtkField stress{"cauchy_stress", 6, {}}, vonMises{"von_mises", 1, {}}, viscous{"viscous_strain", 6, {}};
    VtkField heatFlux{"heat_flux", 3, {}}, cellTemperature{"temperature", 1, {}};
    for (const SolidElement* cell : solid.cells) {
      const Mat3 sigma = cell->meanCauchyStress(z);
      appendSymmetric(sigma, stress.values);
      vonMises.values.push_back(vonMisesOf(sigma));
      appendSymmetric(cell->meanViscousStrain(z), viscous.values);
      if (!thermal) continue;
      const Vec3 flux = cell->meanHeatFlux(z);
      heatFlux.values.insert(heatFlux.values.end(), {flux.x(), flux.y(), flux.z()});
      cellTemperature.values.push_back(cell->meanTemperature(z));
    }
    std::vector<VtkField> cellFields = {stress, vonMises, viscous};
    if (thermal) cellFields.push_back(heatFlux);
    const std::string file = fmt::format("{}/frame_{:05d}.vtu", solid.name, frame_);
    writeVtu((directory_ / file).string(), mesh, s.positions, nodeFields, cellFields);
    s.pvd.add(record.time, file);
    s.pvd.write();
    // the picture shows a thermal solid's temperature, a mechanical one's von Mises stress
    s.picture = thermal ? cellTemperature.values : vonMises.values;
    s.time = record.time;
  }
}

void SolidFrames::finish() {
  for (const Series& s : series_) {
    const std::filesystem::path png = directory_ / (s.solid->name + ".png");
    try {
      renderSurfacePng(png.string(), *s.solid->mesh, s.positions, s.picture,
                       s.solid->thermalDofs.empty() ? "von Mises stress" : "temperature (K)",
                       fmt::format("{} at t = {:.4g}", s.solid->name, s.time));
    } catch (const std::exception& error) {
      fmt::print(stderr, "metriplex: warning: no picture of '{}': {}\n", s.solid->name, error.what());
    }
  }
}

}  // namespace mpx
