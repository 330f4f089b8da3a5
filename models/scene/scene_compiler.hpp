#pragma once
// The scene compiler behind loadScene (internal to models/scene): reads the elements of a
// <metriplex> document in order and builds the model's components with their global dofs.
// scene_compiler.cpp holds the settings and the point-mass/thermal elements,
// scene_multibody.cpp the rigid bodies, joints, joint forces and torques.
#include "models/scene/element_reader.hpp"
#include "models/scene/scene_loader.hpp"

#include "engine/core/time_function.hpp"
#include "models/fe/mesh.hpp"
#include "models/thermal/heat_link.hpp"
#include "models/multibody/joint_builder.hpp"
#include "models/lumped/lumped_element.hpp"

#include <tinyxml2.h>

#include <map>
#include <string>
#include <vector>

namespace mpx {

using tinyxml2::XMLElement;

// How a set of constraints is enforced.
struct ConstraintSettings {
  Enforcement enforcement = Enforcement::AugmentedLagrangian;
  double stiffness = 1e6;
};

class SceneCompiler {
 public:
  SceneCompiler(const XMLElement& root, std::string file, std::optional<ThermalVariable> thermalVariable)
      : root_(root), file_(std::move(file)), thermalOverride_(thermalVariable) {}

  CompiledScene compile();

 private:
  void readSettings();
  void readSimulation(ElementReader& in);
  void readSolver(ElementReader& in);
  void addElement(const XMLElement& element);
  void addMass(ElementReader& in);
  void addAnchor(ElementReader& in);
  void addSpring(ElementReader& in, bool withBranch);
  void addDamper(ElementReader& in);
  void addThermoElement(ElementReader& in, bool withBranch);
  void addReservoir(ElementReader& in);
  void addFixedTemperature(ElementReader& in);
  void addHeatLink(ElementReader& in);
  void addForce(ElementReader& in);
  void addTorque(ElementReader& in);
  void addBody(ElementReader& in);
  void addJoint(ElementReader& in);
  void addJointForce(ElementReader& in);
  // Finite-element solids (scene_solids.cpp).
  void loadSolidMeshes();
  // Position dofs of a <solid> (pre-pass), adding its viscous strains to `internal`.
  int solidPositionDofs(const XMLElement& element, int& internal) const;
  // Nodes a <solid_joint> holds (pre-pass, for its multipliers).
  int solidJointNodes(const XMLElement& element) const;
  void addSolid(ElementReader& in);
  void addTraction(ElementReader& in);
  void addBodyForce(ElementReader& in);
  enum class MotionKind { Clamp, Velocity, Displacement };
  void addPrescribedMotion(ElementReader& in, MotionKind kind);
  void addSolidJoint(ElementReader& in);
  // The solid named by attribute 'solid' and the sorted nodes of its set named by 'surface'.
  const SolidOutput& solidOf(ElementReader& in);
  std::vector<int> solidNodes(ElementReader& in, const SolidOutput& solid);
  // Add one nodal force per entry of `forces` (node -> force), scaled by `profile`.
  void addNodalForces(const std::string& name, const SolidOutput& solid, const std::map<int, Vec3>& forces,
                      const TimeFunction& profile);
  // Penalty or augmented-Lagrangian enforcement of `forms`, with multipliers when needed.
  void addConstraint(const std::string& name, const JointBuilder& builder, std::vector<QuadraticForm> forms,
                     const ConstraintSettings& settings);
  ConstraintSettings constraintSettings(ElementReader& in);
  // Scalar constraints an element adds to the multiplier block (pre-pass count).
  int multipliersOf(const XMLElement& element) const;

  std::string declareName(ElementReader& in);
  Endpoint endpoint(ElementReader& in, const char* attribute);
  std::pair<Endpoint, Endpoint> endpoints(ElementReader& in);
  ThermalNodeRef thermalNode(ElementReader& in, const char* attribute);
  int nextThermalDof(const std::string& name, double scale, int& node);
  // Add a lumped element; its local dofs are what its published node temperature refers to.
  void addLumpedElement(LumpedElementSpec spec);
  Vec3 positionOf(const Endpoint& end) const;
  void keepPositionScale(double length) { positionScale_ = std::max(positionScale_, length); }

  const XMLElement& root_;
  std::string file_;
  std::optional<ThermalVariable> thermalOverride_;
  SceneSettings settings_;
  ThermalVariable variable_ = ThermalVariable::Temperature;
  Vec3 gravity_ = Vec3::Zero();

  Layout layout_;
  Eigen::VectorXd state_, scale_;
  std::vector<std::unique_ptr<Component>> components_;
  std::vector<std::string> thermalNodeNames_;
  std::map<std::string, Endpoint> points_;  // masses and anchors
  std::map<std::string, ThermalNodeRef> thermalNodes_;
  std::map<std::string, int> names_;  // every declared name -> line
  std::map<std::string, Attachment> attachments_;  // what joints may attach to
  // Joints by name, for the force elements on their coordinates.
  struct DeclaredJoint {
    JointType type;
    Attachment a, b;
    JointGeometry geometry;
    double coordinate;  // the joint coordinate's value at t = 0 in the user's convention
  };
  std::map<std::string, DeclaredJoint> joints_;
  std::vector<BodyFrame> bodyFrames_;
  std::vector<JointCoordinate> jointCoordinates_;
  std::map<std::string, std::shared_ptr<const Mesh>> solidMeshes_;  // by solid name, loaded before the layout
  std::vector<SolidOutput> solids_;
  std::vector<PrescribedMotion> prescribedMotions_;
  ConstraintSettings constraintDefaults_;
  int positionCount_ = 0, thermalCount_ = 0, internalCount_ = 0, multiplierCount_ = 0;
  double positionScale_ = 0.0;
};

// The time function of a load: profile="constant|ramp|hat|table" and its parameters.
TimeFunction readProfile(ElementReader& in);

}  // namespace mpx
