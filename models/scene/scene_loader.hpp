#pragma once
// From a scene to a Model: read a scene file (XML or URDF) into a SceneSpec, or build the
// spec in code, then compile it. Scene-level defaults (step, end time, integrator, solver
// settings) come back beside the model, with what output writers need to find bodies,
// joints and solids in the state.
#include "engine/core/model.hpp"
#include "models/multibody/redundant_constraints.hpp"
#include "models/scene/scene_build.hpp"
#include "models/scene/scene_spec.hpp"

#include <memory>
#include <optional>
#include <string>

namespace mpx {

struct CompiledScene {
  std::string name;
  SceneSettings settings;
  std::unique_ptr<Model> model;
  std::vector<BodyFrame> bodies;
  std::vector<JointCoordinate> joints;  // revolute and prismatic joints, for joints.csv
  std::vector<SolidPlacement> solids;
  std::vector<RedundantConditions> redundantConditions;  // their multipliers are held at zero
  // the scene element (its name, else its tag) each of the model's components came from, in
  // the model's order: what a per-element budget sums over
  std::vector<std::string> componentElements;
};

// Throws InputError (file, line, element, what is wrong) on any invalid input. When
// thermalVariable is given it overrides the scene's choice (e.g. --integrator eem-entropy).
CompiledScene compileScene(const SceneSpec& scene, std::optional<ThermalVariable> thermalVariable = std::nullopt);

// Read a scene file: a .urdf alone, or a <metriplex> XML scene.
SceneSpec readScene(const std::string& path);

// readScene then compileScene.
CompiledScene loadScene(const std::string& path, std::optional<ThermalVariable> thermalVariable = std::nullopt);
// The same from XML text; `label` stands for the file name in messages.
CompiledScene loadSceneText(const std::string& text, const std::string& label,
                            std::optional<ThermalVariable> thermalVariable = std::nullopt);

}  // namespace mpx
