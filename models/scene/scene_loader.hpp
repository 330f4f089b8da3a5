#pragma once
// Compile an XML scene (docs/scene-format.md) into a Model. Scene-level defaults (step,
// end time, integrator, solver settings) come back beside the model.
#include "engine/stepping/integrator.hpp"
#include "engine/core/model.hpp"
#include "models/fe/mesh.hpp"
#include "models/fe/solid_element.hpp"
#include "models/multibody/joint_coordinate.hpp"
#include "models/lumped/lumped_element.hpp"

#include <memory>
#include <optional>
#include <string>

namespace mpx {

struct SceneSettings {
  std::string name;
  double dt = 0.0;
  double tEnd = 0.0;
  std::string integrator = "eem";
  ThermalVariable thermalVariable = ThermalVariable::Temperature;  // what the scene declares
  DiscreteGradientForm discreteGradient = DiscreteGradientForm::Partitioned;
  NewtonSettings newton;
};

// A rigid body's pose in a state: centre of mass at firstPositionDof, orientation
// D(t) * directorsToBody with D(t) = [d1 d2 d3] (the body frame as declared in the scene).
struct BodyFrame {
  std::string name;
  int firstPositionDof;
  Eigen::Matrix3d directorsToBody;
};

// A finite-element solid in the state: node n's position at firstPositionDof + 3 n, its
// velocity velocityShift further; its cells (in mesh order) for stresses and output.
struct SolidOutput {
  std::string name;
  std::shared_ptr<const Mesh> mesh;
  int firstPositionDof;
  int velocityShift;
  std::vector<const SolidElement*> cells;
};

struct CompiledScene {
  SceneSettings settings;
  std::unique_ptr<Model> model;
  std::vector<BodyFrame> bodies;
  std::vector<JointCoordinate> joints;  // revolute and prismatic joints, for joints.csv
  std::vector<SolidOutput> solids;
};

// Throws InputError (file, line, element, what is wrong) on any invalid input. When
// thermalVariable is given it overrides the scene's choice (e.g. --integrator eem-entropy).
CompiledScene loadScene(const std::string& path, std::optional<ThermalVariable> thermalVariable = std::nullopt);
// The same from XML text; `label` stands for the file name in messages.
CompiledScene loadSceneText(const std::string& text, const std::string& label,
                            std::optional<ThermalVariable> thermalVariable = std::nullopt);

}  // namespace mpx
