#pragma once
// A scene as data, between the front ends and the compiler: the XML reader, the URDF reader
// and C++ code all produce a SceneSpec, and compileScene (scene_loader.hpp) turns it into a
// Model. Elements carry the tags and attribute names of the XML format, so
// docs/scene-format.md describes both ways of writing a scene and every element's attributes
// are validated by the same reader, whichever front end wrote them; compileScene checks the
// typed settings as the XML reader does.
#include "engine/core/component.hpp"
#include "engine/core/model.hpp"
#include "engine/stepping/integrator.hpp"
#include "models/lumped/lumped_element.hpp"
#include "models/multibody/quadratic_constraint.hpp"

#include <initializer_list>
#include <string>
#include <utility>
#include <vector>

namespace mpx {

// Where an element came from, for messages: a file and line, or (line 0) the label of a
// scene built in code and the element's position in it (index 0: the scene itself).
struct SourceLocation {
  std::string file;
  int line = 0;
  int index = 0;  // 1-based position among the scene's elements
  std::string describe() const;
};

// The value of one attribute as the text the XML format would hold. Numbers are written
// with the shortest representation that reads back to the same double.
class AttributeValue {
 public:
  AttributeValue(const char* text) : text_(text) {}
  AttributeValue(std::string text) : text_(std::move(text)) {}
  AttributeValue(double value);
  AttributeValue(int value);
  AttributeValue(bool value) : text_(value ? "true" : "false") {}
  // a 3-vector, or any Eigen expression of one (Vec3::UnitZ(), 2 * v, ...)
  template <class Derived>
  AttributeValue(const Eigen::MatrixBase<Derived>& value) : AttributeValue(Vec3(value), 0) {
    static_assert(Derived::SizeAtCompileTime == 3, "an attribute vector has 3 components");
  }
  AttributeValue(const std::vector<double>& values);
  AttributeValue(const Eigen::Quaterniond& rotation);  // "w x y z"
  const std::string& text() const { return text_; }

 private:
  AttributeValue(const Vec3& value, int);
  std::string text_;
};

struct Attribute {
  std::string name;
  AttributeValue value;
};

// One scene element: an XML tag (mass, body, joint, solid, ...) and its attributes.
struct ElementSpec {
  std::string tag;
  std::vector<std::pair<std::string, std::string>> attributes;
  SourceLocation where;

  // The attribute's text, or nullptr.
  const std::string* find(const std::string& name) const;
  // Set (or replace) an attribute.
  ElementSpec& set(const std::string& name, const AttributeValue& value);
};

// How a set of constraints is enforced.
struct ConstraintSettings {
  Enforcement enforcement = Enforcement::AugmentedLagrangian;
  double stiffness = 1e6;
};

// What <simulation> and <solver> hold: the run's defaults.
struct SceneSettings {
  double dt = 0.0;    // must be set (> 0)
  double tEnd = 0.0;  // must be set (> 0)
  std::string integrator = "eem";
  ThermalVariable thermalVariable = ThermalVariable::Temperature;  // what the scene declares
  DiscreteGradientForm discreteGradient = DiscreteGradientForm::Partitioned;
  NewtonSettings newton;
  // adaptive steps of the one-step integrators (dt is then the first step) and their
  // tolerances, which IDA uses too; absoluteTolerance 0: relativeTolerance
  bool adaptive = false;
  double relativeTolerance = 1e-6;
  double absoluteTolerance = 0.0;
};

struct SceneSpec {
  std::string name = "scene";
  std::string label = "scene";  // the file it came from, or a name for a scene built in code
  int line = 0;                 // of the root element, for a scene read from a file
  SceneSettings settings;
  Vec3 gravity = Vec3::Zero();
  ConstraintSettings constraints;  // the defaults of bodies, joints and solid joints
  std::vector<ElementSpec> elements;

  // Append an element, e.g. add("mass", {{"name", "m1"}, {"mass", 2.0}, {"position", Vec3(1, 0, 0)}}).
  // Elements may refer only to elements added before them. The reference returned is valid
  // until the next add; the element's location takes the label as it is now.
  ElementSpec& add(const std::string& tag, std::initializer_list<Attribute> attributes = {});
};

}  // namespace mpx
