#pragma once
// The model under construction while a scene compiles (compileScene, scene_loader.hpp), and
// the contract of one element kind. Compilation has two passes over the scene's elements:
//   1. declare: each element says what it needs from the state (DofDemand), reading only
//      what it must (a solid loads its mesh); the layout is the sum of these declarations;
//   2. build: each element builds its components from the dofs the layout assigned it,
//      taken from its DofRange, which refuses more than was declared and reports less.
// Element kinds are registered once, by family, in models/scene/*_elements.cpp.
#include "engine/core/layout.hpp"
#include "models/fe/mesh.hpp"
#include "models/fe/solid_element.hpp"
#include "models/multibody/joint_builder.hpp"
#include "models/multibody/joint_coordinate.hpp"
#include "models/multibody/redundant_constraints.hpp"
#include "models/scene/element_reader.hpp"
#include "models/scene/scene_spec.hpp"
#include "models/thermal/heat_link.hpp"

#include <map>
#include <memory>
#include <string>
#include <vector>

namespace mpx {

// State dofs one element owns: position dofs (each with its velocity), thermal, internal and
// multiplier dofs.
struct DofDemand {
  int positions = 0;
  int thermal = 0;
  int internal = 0;
  int multipliers = 0;
};

// The dofs the layout assigned to one element, handed out in order as it builds.
class DofRange {
 public:
  DofRange(const Layout& layout, const DofDemand& first, const DofDemand& declared);
  // Global index of the first of `count` consecutive new dofs of `block` (Position,
  // Thermal, Internal or Multiplier; -1 for count 0). Throws std::logic_error beyond the
  // declaration.
  int take(Block block, int count);
  // Throws std::logic_error naming `where` if some declared dof was not taken.
  void checkAllTaken(const std::string& where) const;

 private:
  static int of(const DofDemand& demand, Block block);
  static int& of(DofDemand& demand, Block block);
  const Layout& layout_;
  DofDemand first_, declared_, taken_;
};

// A rigid body's pose in a state: centre of mass at firstPositionDof, orientation
// D(t) * directorsToBody with D(t) = [d1 d2 d3] (the body frame as declared in the scene).
struct BodyFrame {
  std::string name;
  int firstPositionDof;
  Eigen::Matrix3d directorsToBody;
};

// Where a finite-element solid sits in the state: node n's position at firstPositionDof + 3 n,
// its velocity velocityShift further; its cells (in mesh order) for stresses and output.
struct SolidPlacement {
  std::string name;
  std::shared_ptr<const Mesh> mesh;
  int firstPositionDof;
  int velocityShift;
  std::vector<const SolidElement*> cells;
  std::vector<int> thermalDofs;          // each node's thermal dof; empty for a purely mechanical solid
  NodalThermalVariable thermalVariable;  // what those dofs hold

  double nodeTemperature(const double* z, int node) const { return thermalVariable.temperature(z[thermalDofs[node]]); }
};

// A joint as later elements (joint forces) need it.
struct DeclaredJoint {
  JointType type;
  Attachment a, b;
  JointGeometry geometry;
  double coordinate;  // the joint coordinate's value at t = 0 in the user's convention
};

class SceneBuild {
 public:
  SceneBuild(const SceneSpec& spec, ThermalVariable variable) : spec(spec), variable(variable) {}
  SceneBuild(SceneSpec&&, ThermalVariable) = delete;

  const SceneSpec& spec;  // outlives the build (compileScene's argument)
  const ThermalVariable variable;

  // Filled by the declare pass.
  std::map<const ElementSpec*, std::shared_ptr<const Mesh>> meshOfSolid;
  std::map<std::string, std::shared_ptr<const Mesh>> meshByName;  // the first solid of each name
  std::map<std::string, JointType> jointTypes;                    // the first joint of each name

  // Filled by the build pass.
  Layout layout;
  Eigen::VectorXd state, scale;  // initial state; Newton's scale per dof (0: not set)
  std::vector<std::unique_ptr<Component>> components;
  std::vector<ConstraintEdge> constraints;  // among components: joints and body rigidity
  std::vector<std::string> thermalNodeNames;
  std::map<std::string, Endpoint> points;         // masses, anchors, bodies' centres
  std::map<std::string, Attachment> attachments;  // what joints may attach to
  std::map<std::string, ThermalNodeRef> thermalNodes;
  std::map<std::string, DeclaredJoint> joints;
  std::vector<BodyFrame> bodyFrames;
  std::vector<JointCoordinate> jointCoordinates;
  std::vector<SolidPlacement> solids;
  std::vector<PrescribedMotion> prescribedMotions;
  std::vector<double> loadBreakpoints;  // of every load profile read
  double positionScale = 0.0;           // the largest length seen, for Newton's position scale

  void allocate(const Layout& assigned);
  int velocityShift() const { return layout.offset(Block::Velocity) - layout.offset(Block::Position); }

  // The element's name, checked unique.
  std::string declareName(ElementReader& in);
  // The mass or anchor named by `attribute`.
  Endpoint endpoint(ElementReader& in, const char* attribute) const;
  // The end point `attribute` of a two-point element, at the body point `pointAttribute`
  // (world coordinates at t = 0, moving with the body) when that is given.
  Endpoint endpointAt(ElementReader& in, const char* attribute, const char* pointAttribute) const;
  // Ends 'a' and 'b' of a two-point element (at 'a_point', 'b_point'), apart, not on one body.
  std::pair<Endpoint, Endpoint> endpoints(ElementReader& in);
  // The body, mass or anchor named by `attribute`.
  const Attachment& attachment(ElementReader& in, const char* attribute) const;
  Vec3 positionOf(const Endpoint& end) const;
  void keepPositionScale(double length) { positionScale = std::max(positionScale, length); }

  // The thermal node named by `attribute`.
  ThermalNodeRef thermalNode(ElementReader& in, const char* attribute) const;
  // Register the thermal node `name` held by `dof` (-1: a prescribed temperature); returns
  // its node index.
  int addThermalNode(const std::string& name, int dof, double scale);
  void addComponent(std::unique_ptr<Component> component) { components.push_back(std::move(component)); }
  // Add the component that owns thermal node `node`: the node learns the component's local
  // dofs, which the derivative of its published temperature refers to.
  void addThermalNodeOwner(const std::string& node, std::unique_ptr<Component> component);

  // enforcement="..." and stiffness="..." of a constraint element, over the scene defaults.
  ConstraintSettings constraintSettings(ElementReader& in) const;
  // Whether an element's constraints take multipliers (declare pass: no validation).
  bool takesMultipliers(const ElementReader& in) const;
  // Penalty or augmented-Lagrangian enforcement of `forms`, with multipliers when needed;
  // `leadingGap`: forms 0-2 are the components of the gap between two points (coincidesPoints).
  void addConstraint(const std::string& name, const JointBuilder& builder, std::vector<QuadraticForm> forms,
                     bool leadingGap, const ConstraintSettings& settings, DofRange& dofs);

  // The solid named by attribute 'solid', and the sorted nodes of its set named by 'surface'.
  const SolidPlacement& solidOf(ElementReader& in) const;
  std::vector<int> solidNodes(ElementReader& in, const SolidPlacement& solid) const;

 private:
  std::map<std::string, SourceLocation> names_;  // every declared name -> where
};

// One element kind of the scene format: its tag, what it declares, how it builds.
struct ElementKind {
  const char* tag;
  DofDemand (*declare)(ElementReader& in, SceneBuild& build);  // nullptr: owns no dofs
  void (*build)(ElementReader& in, SceneBuild& build, DofRange& dofs);
};

// The element kinds of each family (models/scene/<family>_elements.cpp).
const std::vector<ElementKind>& lumpedElementKinds();
const std::vector<ElementKind>& thermalElementKinds();
const std::vector<ElementKind>& multibodyElementKinds();
const std::vector<ElementKind>& solidElementKinds();
const std::vector<ElementKind>& thermalSolidElementKinds();

// A <solid>'s thermal material (heat_capacity, conductivity, expansion, reference_temperature,
// viscosity_activation), or none when it gives no heat_capacity.
std::optional<ThermalMaterial> readThermalMaterial(ElementReader& in, const LameParameters& lame);
// Give a thermal solid its nodal thermal dofs (the build's thermal variable), at its initial 'temperature'.
void takeTemperatures(ElementReader& in, SceneBuild& build, DofRange& dofs, const ThermalMaterial& m,
                      SolidPlacement& solid);

// The kind registered for `tag`, or nullptr; all tags, for messages.
const ElementKind* findElementKind(const std::string& tag);
std::string elementTags();

// Names that become file or directory names under the output directory (the scene's, a
// solid's) must be 1 to 64 of A-Z a-z 0-9 _ - . + and not start with '.', so that no name can
// reach outside the output directory. Returns what is wrong with `name` (quoted by echoed()),
// or "".
std::string fileNameProblem(const std::string& name);

// The time function of a load: profile="constant|ramp|hat|sine_pulse|table" and its parameters.
// Its breakpoints join the build's, where adaptive steps land.
TimeFunction readProfile(ElementReader& in, SceneBuild& build);

}  // namespace mpx
