#include "models/scene/urdf_import.hpp"

#include "engine/core/input_error.hpp"
#include "models/scene/input_file.hpp"

#include "models/scene/strict_xml.hpp"

#include <tinyxml2.h>

#include <console_bridge/console.h>
#include <urdf_parser/urdf_parser.h>

#include <Eigen/Eigenvalues>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <iostream>
#include <utility>
#include <vector>

namespace mpx {

namespace {

using Pose = Eigen::Isometry3d;

// Velocity below which the joint force of a URDF <dynamics> smooths Coulomb friction (rad/s or m/s).
constexpr double kFrictionVelocity = 0.01;

Vec3 toEigen(const urdf::Vector3& v) { return {v.x, v.y, v.z}; }

Pose toEigen(const urdf::Pose& p) {
  Pose pose = Pose::Identity();
  pose.translate(toEigen(p.position));
  pose.rotate(Eigen::Quaterniond(p.rotation.w, p.rotation.x, p.rotation.y, p.rotation.z));
  return pose;
}

// Space-separated numbers for messages.
std::string numbers(const Vec3& v) { return AttributeValue(v).text(); }
std::string number(double value) { return AttributeValue(value).text(); }

// 'a', 'b', 'c' for messages; a long list is cut after the first few names.
std::string quotedList(const std::vector<std::string>& names) {
  constexpr std::size_t kListed = 8;
  std::string list;
  for (std::size_t i = 0; i < std::min(names.size(), kListed); ++i) list += (i == 0 ? "'" : ", '") + names[i] + "'";
  if (names.size() > kListed) list += " and " + std::to_string(names.size() - kListed) + " more";
  return list;
}

void warn(const std::string& path, const std::string& message) {
  std::cerr << "metriplex: warning: " << path << ": " << message << "\n";
}

bool hasCoordinate(const urdf::Joint& joint) {
  return joint.type == urdf::Joint::REVOLUTE || joint.type == urdf::Joint::CONTINUOUS ||
         joint.type == urdf::Joint::PRISMATIC;
}

// The scene's joint type for a URDF joint; floating joints have none (the child moves freely).
const char* sceneJointType(const urdf::Joint& joint) {
  switch (joint.type) {
    case urdf::Joint::REVOLUTE:
    case urdf::Joint::CONTINUOUS:
      return "revolute";
    case urdf::Joint::PRISMATIC:
      return "prismatic";
    case urdf::Joint::PLANAR:
      return "planar";
    case urdf::Joint::FIXED:
      return "fixed";
    default:
      return nullptr;
  }
}

// The URDF text and the lines of its <link> and <joint> elements: urdfdom keeps no line
// numbers, so messages find them here.
class UrdfFile {
 public:
  explicit UrdfFile(std::string path) : path_(std::move(path)), text_(readInputFile(path_, "URDF file")) {
    tinyxml2::XMLDocument document;
    const tinyxml2::XMLElement& robot = parseStrictXml(document, text_, path_, TextContent::Allowed);
    for (const tinyxml2::XMLElement* e = robot.FirstChildElement(); e; e = e->NextSiblingElement())
      if (const char* name = e->Attribute("name")) lines_.emplace(key(e->Name(), name), e->GetLineNum());
    checkNoPercent(robot);
    checkJointTree(robot);
  }

  const std::string& path() const { return path_; }
  const std::string& text() const { return text_; }
  // Line of <kind name="name">, 0 if unknown.
  int line(const std::string& kind, const std::string& name) const {
    const auto found = lines_.find(key(kind, name));
    return found == lines_.end() ? 0 : found->second;
  }

  // Throw an InputError at <kind name="name">, kind "link" or "joint".
  [[noreturn]] void fail(const std::string& kind, const std::string& name, const std::string& message) const {
    const std::string what = "<" + kind + " name=\"" + name + "\">: " + message;
    const auto line = lines_.find(key(kind, name));
    if (line == lines_.end()) throw InputError(path_ + ": " + what);
    throw InputError(path_, line->second, what);
  }

 private:
  static std::string key(const std::string& kind, const std::string& name) { return kind + " " + name; }

  // urdfdom writes some of its messages with the value it rejects as the printf format, so a
  // '%' there would be read as a directive and read memory that is not there (the fuzzer found
  // a mass of "...%77777777s..."): no attribute value or text may hold one. (The recursion is
  // as deep as the file's nesting, which tinyxml2 limits to TINYXML2_MAX_ELEMENT_DEPTH = 100.)
  void checkNoPercent(const tinyxml2::XMLElement& element) const {
    for (const tinyxml2::XMLAttribute* a = element.FirstAttribute(); a; a = a->Next())
      if (std::strchr(a->Value(), '%'))
        throw InputError(path_, a->GetLineNum(),
                         "<" + std::string(element.Name()) + ">: attribute '" + a->Name() +
                             "' holds a '%', which urdfdom's messages would read as a printf directive");
    if (const char* text = element.GetText(); text && std::strchr(text, '%'))
      throw InputError(path_, element.GetLineNum(),
                       "<" + std::string(element.Name()) +
                           ">: its text holds a '%', which urdfdom's messages would read as a printf directive");
    for (const tinyxml2::XMLElement* child = element.FirstChildElement(); child; child = child->NextSiblingElement())
      checkNoPercent(*child);
  }

  // The joints must form a tree before urdfdom sees them: it links parents and children by
  // shared_ptr, and links on a cycle would own each other and never be freed (the fuzzer found
  // a joint from a link to itself).
  void checkJointTree(const tinyxml2::XMLElement& robot) const {
    std::map<std::string, std::string> parentOf, jointTo;  // per child link: its parent link, its joint
    for (const tinyxml2::XMLElement* e = robot.FirstChildElement("joint"); e; e = e->NextSiblingElement("joint")) {
      const tinyxml2::XMLElement* parentElement = e->FirstChildElement("parent");
      const tinyxml2::XMLElement* childElement = e->FirstChildElement("child");
      const char* name = e->Attribute("name");
      const char* parent = parentElement ? parentElement->Attribute("link") : nullptr;
      const char* child = childElement ? childElement->Attribute("link") : nullptr;
      if (!name || !parent || !child) continue;  // urdfdom names what is missing
      if (std::string(parent) == child)
        fail("joint", name, "has link '" + std::string(child) + "' as both parent and child: a URDF must be a tree");
      const auto [reached, first] = jointTo.emplace(child, name);
      if (!first)
        fail("link", child,
             "is the child of two joints, '" + reached->second + "' and '" + name + "': a URDF must be a tree");
      parentOf[child] = parent;
    }
    // follow each link's parents up to a root; a walk that meets itself is a cycle
    enum Mark { Unseen, OnWalk, LeadsToRoot };
    std::map<std::string, Mark> marks;
    for (const auto& [start, parent] : parentOf) {
      std::vector<std::string> walk;
      std::string link = start;
      for (; marks[link] == Unseen && parentOf.count(link); link = parentOf.at(link)) {
        marks[link] = OnWalk;
        walk.push_back(link);
      }
      if (marks[link] == OnWalk)
        fail("link", link, "is on a cycle of joints (one is '" + jointTo.at(link) + "'): a URDF must be a tree");
      for (const std::string& reached : walk) marks[reached] = LeadsToRoot;
    }
  }

  std::string path_, text_;
  std::map<std::string, int> lines_;
};

// urdfdom reports problems through console_bridge and may still return a model (a mass it
// could not parse is left at 0), so while it parses its errors are collected to reject the
// file and its warnings go to stderr.
class ParserLog final : public console_bridge::OutputHandler {
 public:
  explicit ParserLog(std::string path) : path_(std::move(path)) { console_bridge::useOutputHandler(this); }
  ~ParserLog() override { console_bridge::restorePreviousOutputHandler(); }
  ParserLog(const ParserLog&) = delete;
  ParserLog& operator=(const ParserLog&) = delete;

  void log(const std::string& text, console_bridge::LogLevel level, const char*, int) override {
    if (level >= console_bridge::CONSOLE_BRIDGE_LOG_ERROR)
      errors_ += (errors_.empty() ? "" : "; ") + text;
    else if (level == console_bridge::CONSOLE_BRIDGE_LOG_WARN)
      warn(path_, text);
  }
  const std::string& errors() const { return errors_; }

 private:
  std::string path_, errors_;
};

urdf::ModelInterfaceSharedPtr parse(const UrdfFile& file) {
  const ParserLog log(file.path());
  const urdf::ModelInterfaceSharedPtr robot = urdf::parseURDF(file.text());
  if (!robot || !log.errors().empty())
    throw InputError(file.path() + ": invalid URDF: " + (log.errors().empty() ? "urdfdom rejects it" : log.errors()));
  return robot;
}

// A link at t = 0 and what carries it in the scene.
struct LinkState {
  Pose frame = Pose::Identity();  // world pose of the link frame
  Vec3 angularVelocity = Vec3::Zero();
  Vec3 originVelocity = Vec3::Zero();  // velocity of the frame's origin
  std::string carrier;  // scene name of its body, or of the body or anchor a massless link is merged into
};

// Walks the tree from the root, parents before children, and emits each link's elements as
// it reaches them, so every reference is declared above its use.
class UrdfTranslator {
 public:
  UrdfTranslator(const UrdfFile& file, const urdf::ModelInterface& robot, const UrdfImportOptions& options,
                 SceneSpec& scene)
      : file_(file), robot_(robot), options_(options), scene_(scene) {}

  void translate();

 private:
  // Joint names must not be link names; initial states must name joints with a coordinate.
  void checkNames() const;
  std::string addRoot(const urdf::Link& root, const LinkState& state);
  void addDescendants(const urdf::Link& root, const LinkState& rootState);
  // Emits `child`, reached from its parent through `joint`; returns its state.
  LinkState addChild(const urdf::Joint& joint, const urdf::Link& child, const LinkState& parentState);
  LinkState childState(const urdf::Joint& joint, const LinkState& parent) const;
  UrdfJointState initialState(const urdf::Joint& joint) const;
  Vec3 unitAxis(const urdf::Joint& joint) const;
  static bool massless(const urdf::Link& link);
  void addBody(const urdf::Link& link, const LinkState& state);
  // The link's inertia tensor, checked; balanced when the options allow it.
  Eigen::Matrix3d checkedInertia(const urdf::Link& link, const Eigen::Matrix3d& tensor) const;
  void addJoint(const urdf::Joint& joint, const LinkState& parent, const LinkState& child);
  void addDynamics(const urdf::Joint& joint);
  void addStops(const urdf::Joint& joint);
  void reportIgnored() const;
  std::string sceneName(const std::string& urdfName) const { return options_.prefix + urdfName; }
  // A new scene element named `urdfName` (prefixed), made from the URDF's <kind name="source">.
  ElementSpec& emit(const char* tag, const std::string& urdfName, const char* kind, const std::string& source);

  const UrdfFile& file_;
  const urdf::ModelInterface& robot_;
  const UrdfImportOptions& options_;
  SceneSpec& scene_;
  std::vector<std::string> limitedJoints_, fullTurnLimits_, ignoredDynamics_;
};

void UrdfTranslator::translate() {
  checkNames();
  const urdf::Link& root = *robot_.getRoot();
  LinkState state;
  state.frame = Eigen::Translation3d(options_.position) * options_.orientation;
  state.carrier = addRoot(root, state);
  addDescendants(root, state);
  reportIgnored();
}

void UrdfTranslator::checkNames() const {
  // a scene name belongs to one element, but URDF links and joints have separate name spaces
  for (const auto& [name, joint] : robot_.joints_)
    if (robot_.links_.count(name))
      file_.fail("joint", name, "has the name of a link, and scene names must be unique: rename one of them");
  for (const auto& [name, state] : options_.initial) {
    const urdf::JointConstSharedPtr joint = robot_.getJoint(name);
    if (!joint)
      throw InputError(file_.path() + ": an initial state is given for joint '" + name +
                       "', which the URDF does not have");
    if (!hasCoordinate(*joint))
      file_.fail("joint", name,
                 "takes no initial position or velocity (only revolute, continuous and prismatic "
                 "joints have one coordinate)");
  }
}

std::string UrdfTranslator::addRoot(const urdf::Link& root, const LinkState& state) {
  const Vec3 origin = state.frame.translation();
  // the world-link idiom: a massless root is the ground itself
  if (massless(root)) {
    if (options_.floating) file_.fail("link", root.name, "a floating root link needs an <inertial> with positive mass");
    emit("anchor", root.name, "link", root.name).set("position", origin);
    return sceneName(root.name);
  }
  addBody(root, state);
  // a root with mass is held by a fixed joint to an anchor at its frame
  if (!options_.floating) {
    emit("anchor", root.name + ".ground", "link", root.name).set("position", origin);
    emit("joint", root.name + ".fixed", "link", root.name)
        .set("type", "fixed")
        .set("a", sceneName(root.name + ".ground"))
        .set("b", sceneName(root.name))
        .set("anchor", origin);
  }
  return sceneName(root.name);
}

void UrdfTranslator::addDescendants(const urdf::Link& root, const LinkState& rootState) {
  // depth first with an explicit stack (a chain of links may be deeper than the call stack), in
  // the order of a recursive walk: a link's whole subtree before its next sibling
  std::vector<std::pair<const urdf::Joint*, LinkState>> pending;
  auto pushChildJoints = [&](const urdf::Link& parent, const LinkState& state) {
    for (auto joint = parent.child_joints.rbegin(); joint != parent.child_joints.rend(); ++joint)
      pending.emplace_back(joint->get(), state);
  };
  pushChildJoints(root, rootState);
  while (!pending.empty()) {
    const auto [joint, parentState] = std::move(pending.back());
    pending.pop_back();
    const urdf::Link& child = *robot_.getLink(joint->child_link_name);
    pushChildJoints(child, addChild(*joint, child, parentState));
  }
}

LinkState UrdfTranslator::addChild(const urdf::Joint& joint, const urdf::Link& child, const LinkState& parentState) {
  if (joint.mimic)
    file_.fail("joint", joint.name,
               "mimics joint '" + joint.mimic->joint_name +
                   "': mimic joints are not supported (import it as an independent joint)");
  LinkState state = childState(joint, parentState);
  if (massless(child)) {
    // a massless link rigidly fixed to its parent is merged into the parent's carrier
    if (joint.type != urdf::Joint::FIXED)
      file_.fail("link", child.name,
                 "has no mass (no <inertial>, or mass and inertia 0) but joint '" + joint.name +
                     "' moves it: give it a positive mass or fix it to its parent");
    state.carrier = parentState.carrier;
  } else {
    addBody(child, state);
    state.carrier = sceneName(child.name);
    if (joint.type != urdf::Joint::FLOATING) addJoint(joint, parentState, state);
  }
  addDynamics(joint);
  return state;
}

LinkState UrdfTranslator::childState(const urdf::Joint& joint, const LinkState& parent) const {
  const UrdfJointState q = initialState(joint);
  LinkState child;
  child.frame = parent.frame * toEigen(joint.parent_to_joint_origin_transform);
  if (!child.frame.matrix().allFinite()) file_.fail("joint", joint.name, "the <origin> must be finite");
  // the joint's own motion: its axis stays put in world coordinates while the child moves along it
  Vec3 worldAxis = Vec3::Zero(), spin = Vec3::Zero(), slide = Vec3::Zero();
  if (hasCoordinate(joint)) {
    const Vec3 axis = unitAxis(joint);
    worldAxis = child.frame.linear() * axis;
    if (joint.type == urdf::Joint::PRISMATIC) {
      child.frame.translate(q.position * axis);
      slide = q.velocity * worldAxis;
    } else {
      child.frame.rotate(Eigen::AngleAxisd(q.position, axis));
      spin = q.velocity * worldAxis;
    }
  }
  // rigid motion with the parent plus the joint rate
  child.angularVelocity = parent.angularVelocity + spin;
  child.originVelocity = parent.originVelocity +
                         parent.angularVelocity.cross(child.frame.translation() - parent.frame.translation()) + slide;
  return child;
}

UrdfJointState UrdfTranslator::initialState(const urdf::Joint& joint) const {
  const auto initial = options_.initial.find(joint.name);
  return initial == options_.initial.end() ? UrdfJointState{} : initial->second;
}

Vec3 UrdfTranslator::unitAxis(const urdf::Joint& joint) const {
  const Vec3 axis = toEigen(joint.axis);
  if (!axis.allFinite() || !(axis.norm() > 0.0))
    file_.fail("joint", joint.name, "the <axis> must be a non-zero vector");
  return axis.normalized();
}

bool UrdfTranslator::massless(const urdf::Link& link) {
  if (!link.inertial) return true;
  const urdf::Inertial& i = *link.inertial;
  return i.mass == 0.0 && i.ixx == 0.0 && i.iyy == 0.0 && i.izz == 0.0 && i.ixy == 0.0 && i.ixz == 0.0 && i.iyz == 0.0;
}

void UrdfTranslator::addBody(const urdf::Link& link, const LinkState& state) {
  const urdf::Inertial& i = *link.inertial;
  if (!(i.mass > 0.0) || !std::isfinite(i.mass))
    file_.fail("link", link.name, "mass must be positive and finite, got " + number(i.mass));
  Eigen::Matrix3d tensor;
  tensor << i.ixx, i.ixy, i.ixz, i.ixy, i.iyy, i.iyz, i.ixz, i.iyz, i.izz;
  tensor = checkedInertia(link, tensor);
  // the tensor is given about the centre of mass in the inertial frame: the body's orientation
  const Pose inertialFrame = state.frame * toEigen(i.origin);
  const Vec3 centre = inertialFrame.translation();
  const Eigen::Quaterniond q(inertialFrame.linear());
  const Vec3 velocity = state.originVelocity + state.angularVelocity.cross(centre - state.frame.translation());
  emit("body", link.name, "link", link.name)
      .set("mass", i.mass)
      .set("inertia",
           std::vector<double>{tensor(0, 0), tensor(1, 1), tensor(2, 2), tensor(0, 1), tensor(0, 2), tensor(1, 2)})
      .set("position", centre)
      .set("orientation", q)
      .set("velocity", velocity)
      .set("angular_velocity", state.angularVelocity);
}

// A director body's "masses" (J_j + J_k - J_i)/2 must be positive: principal moments need the
// strict triangle inequality. A tensor that violates it is rejected, or with balance_inertia
// its two smaller moments are raised by the same amount until J_1 + J_2 = (1 + margin) J_3, in
// the same principal axes.
Eigen::Matrix3d UrdfTranslator::checkedInertia(const urdf::Link& link, const Eigen::Matrix3d& tensor) const {
  constexpr double kBalanceMargin = 1e-2;
  if (!tensor.allFinite()) file_.fail("link", link.name, "the inertia must be finite");
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> principal(tensor);
  const Vec3 J = principal.eigenvalues();
  if (!(J[0] > 0.0))
    file_.fail("link", link.name,
               "the inertia tensor must be positive definite; its principal moments are " + numbers(J));
  if (J[0] + J[1] > J[2]) return tensor;
  if (!options_.balanceInertia)
    file_.fail("link", link.name,
               "the principal moments " + numbers(J) +
                   " violate the strict triangle inequality J_i < J_j + J_k that rigid bodies need "
                   "(<urdf balance_inertia=\"true\"> raises them)");
  const double raise = 0.5 * ((1.0 + kBalanceMargin) * J[2] - J[0] - J[1]);
  const Vec3 balanced(J[0] + raise, J[1] + raise, J[2]);
  warn(file_.path(), "link '" + link.name + "': principal moments " + numbers(J) +
                         " violate the triangle inequality J_i < J_j + J_k; balance_inertia raised them to " +
                         numbers(balanced));
  return principal.eigenvectors() * balanced.asDiagonal() * principal.eigenvectors().transpose();
}

void UrdfTranslator::addJoint(const urdf::Joint& joint, const LinkState& parent, const LinkState& child) {
  ElementSpec& element = emit("joint", joint.name, "joint", joint.name)
                             .set("type", sceneJointType(joint))
                             .set("a", parent.carrier)
                             .set("b", child.carrier)
                             .set("anchor", Vec3(child.frame.translation()));
  if (joint.type != urdf::Joint::FIXED) element.set("axis", Vec3(child.frame.linear() * unitAxis(joint)));
  // joints.csv then reports the URDF's own joint coordinate
  if (hasCoordinate(joint)) element.set("coordinate", initialState(joint).position);
}

void UrdfTranslator::addDynamics(const urdf::Joint& joint) {
  if ((joint.type == urdf::Joint::REVOLUTE || joint.type == urdf::Joint::PRISMATIC) && joint.limits &&
      joint.limits->lower < joint.limits->upper) {
    if (options_.limits)
      addStops(joint);
    else
      limitedJoints_.push_back(joint.name);
  }
  if (!joint.dynamics || (joint.dynamics->damping == 0.0 && joint.dynamics->friction == 0.0)) return;
  if (!(joint.dynamics->damping >= 0.0 && joint.dynamics->friction >= 0.0) || !std::isfinite(joint.dynamics->damping) ||
      !std::isfinite(joint.dynamics->friction))
    file_.fail("joint", joint.name, "damping and friction must be finite and not negative");
  if (!hasCoordinate(joint)) {
    ignoredDynamics_.push_back(joint.name);
    return;
  }
  auto& force = emit("joint_force", joint.name + ".damping", "joint", joint.name)
                    .set("joint", sceneName(joint.name))
                    .set("damping", joint.dynamics->damping)
                    .set("friction", joint.dynamics->friction);
  if (joint.dynamics->friction > 0.0) force.set("friction_velocity", kFrictionVelocity);
}

// Stops at the joint's position limits, in the URDF's coordinate (the scene joint's `coordinate`).
void UrdfTranslator::addStops(const urdf::Joint& joint) {
  const double lower = joint.limits->lower, upper = joint.limits->upper;
  if (!std::isfinite(lower) || !std::isfinite(upper)) file_.fail("joint", joint.name, "the limits must be finite");
  // a revolute stop's chart spans less than a full turn
  if (joint.type == urdf::Joint::REVOLUTE && !(upper - lower < 2.0 * M_PI)) {
    fullTurnLimits_.push_back(joint.name);
    return;
  }
  emit("joint_force", joint.name + ".limits", "joint", joint.name)
      .set("joint", sceneName(joint.name))
      .set("lower", lower)
      .set("upper", upper)
      .set("limit_stiffness", options_.limitStiffness)
      .set("limit_damping", options_.limitDamping);
}

void UrdfTranslator::reportIgnored() const {
  if (!limitedJoints_.empty())
    warn(file_.path(), "position limits of joints " + quotedList(limitedJoints_) +
                           " are ignored (no joint stops; <urdf limits=\"true\"> adds them)");
  if (!fullTurnLimits_.empty())
    warn(file_.path(), "position limits of joints " + quotedList(fullTurnLimits_) +
                           " span a full turn or more and are ignored (joint stops need a range below 2 pi)");
  if (!ignoredDynamics_.empty())
    warn(file_.path(), "damping and friction of joints " + quotedList(ignoredDynamics_) +
                           " are ignored (joint forces act on revolute, continuous and prismatic joints only)");
}

ElementSpec& UrdfTranslator::emit(const char* tag, const std::string& urdfName, const char* kind,
                                  const std::string& source) {
  ElementSpec& element = scene_.add(tag, {{"name", sceneName(urdfName)}});
  element.where = {file_.path(), file_.line(kind, source), static_cast<int>(scene_.elements.size())};
  return element;
}

}  // namespace

void appendUrdfElements(const std::string& path, const UrdfImportOptions& options, SceneSpec& scene) {
  const UrdfFile file(path);
  const urdf::ModelInterfaceSharedPtr robot = parse(file);
  UrdfTranslator(file, *robot, options, scene).translate();
}

}  // namespace mpx
