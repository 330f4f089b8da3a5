#include "models/scene/scene_build.hpp"

#include <algorithm>
#include <array>
#include <cctype>
#include <stdexcept>

namespace mpx {

DofRange::DofRange(const Layout& layout, const DofDemand& first, const DofDemand& declared)
    : layout_(layout), first_(first), declared_(declared) {}

int& DofRange::of(DofDemand& demand, Block block) {
  switch (block) {
    case Block::Position:
      return demand.positions;
    case Block::Thermal:
      return demand.thermal;
    case Block::Internal:
      return demand.internal;
    case Block::Multiplier:
      return demand.multipliers;
    case Block::Velocity:
      break;
  }
  throw std::logic_error("velocity dofs come with their positions");
}

int DofRange::of(const DofDemand& demand, Block block) { return of(const_cast<DofDemand&>(demand), block); }

int DofRange::take(Block block, int count) {
  if (count == 0) return -1;
  int& taken = of(taken_, block);
  if (taken + count > of(declared_, block))
    throw std::logic_error("an element builds more " + std::string(blockName(block)) + " dofs (" +
                           std::to_string(taken + count) + ") than it declared (" +
                           std::to_string(of(declared_, block)) + ")");
  const int dof = layout_.dof(block, of(first_, block) + taken);
  taken += count;
  return dof;
}

void DofRange::checkAllTaken(const std::string& where) const {
  for (Block block : {Block::Position, Block::Thermal, Block::Internal, Block::Multiplier})
    if (of(taken_, block) != of(declared_, block))
      throw std::logic_error(where + ": the element declared " + std::to_string(of(declared_, block)) + " " +
                             std::string(blockName(block)) + " dofs but built " + std::to_string(of(taken_, block)));
}

namespace {

// The entry of `named` that attribute `attribute` names; otherwise fail with "no <kinds> named
// '...' <declaredWhere>".
template <class Map>
const typename Map::mapped_type& declared(const Map& named, ElementReader& in, const char* attribute, const char* kinds,
                                          const char* declaredWhere) {
  const std::string name = in.text(attribute);
  const auto it = named.find(name);
  if (it == named.end())
    in.fail(std::string("attribute '") + attribute + "': no " + kinds + " named '" + name + "' " + declaredWhere);
  return it->second;
}

}  // namespace

void SceneBuild::allocate(const Layout& assigned) {
  layout = assigned;
  state = Eigen::VectorXd::Zero(layout.total());
  scale = Eigen::VectorXd::Zero(layout.total());
}

std::string SceneBuild::declareName(ElementReader& in) {
  const std::string name = in.text("name");
  if (name.empty()) in.fail("name must not be empty");
  // names head CSV columns and label plots: a comma or quote would shift the columns, a newline the rows
  const bool plain = std::none_of(name.begin(), name.end(),
                                  [](unsigned char c) { return c < 0x20 || c == 0x7f || c == ',' || c == '"'; });
  if (!plain)
    in.fail("name '" + echoed(name) + "' heads CSV columns, so it must hold no comma, quote or control character");
  const auto [first, inserted] = names_.emplace(name, in.element().where);
  if (!inserted) {
    const SourceLocation& there = first->second;
    const bool sameFile = there.line > 0 && there.file == in.element().where.file;
    in.fail("name '" + name + "' is already used " +
            (sameFile ? "on line " + std::to_string(there.line) : "at " + there.describe()));
  }
  return name;
}

Endpoint SceneBuild::endpoint(ElementReader& in, const char* attribute) const {
  return declared(points, in, attribute, "mass or anchor", "declared above this element");
}

Vec3 SceneBuild::positionOf(const Endpoint& end) const { return end.in(state.data()); }

Endpoint SceneBuild::endpointAt(ElementReader& in, const char* attribute, const char* pointAttribute) const {
  if (!in.has(pointAttribute)) return endpoint(in, attribute);
  const Attachment& body = attachment(in, attribute);
  if (body.kind != Attachment::Kind::Body)
    in.fail(std::string("attribute '") + pointAttribute + "': '" + in.text(attribute) +
            "' is not a body (only a body has points besides its position)");
  // body coordinates X = D0^T (p - phi0), as a joint's anchor
  const Vec3 X = body.directors.transpose() * (in.vector(pointAttribute, body.position) - body.position);
  return Endpoint::bodyPoint(body.firstPositionDof, body.firstPositionDof + velocityShift(), X);
}

std::pair<Endpoint, Endpoint> SceneBuild::endpoints(ElementReader& in) {
  const Endpoint a = endpointAt(in, "a", "a_point"), b = endpointAt(in, "b", "b_point");
  // two points of one body keep their distance (and would share dofs)
  if (a.moves() && a.positionDof == b.positionDof && (a.terms > 1 || b.terms > 1))
    in.fail("end points 'a' and 'b' are on the same body: their distance cannot change");
  const double length = (positionOf(b) - positionOf(a)).norm();
  if (!(length > 0.0)) in.fail("end points 'a' and 'b' coincide: the element has no direction");
  keepPositionScale(length);
  return {a, b};
}

const Attachment& SceneBuild::attachment(ElementReader& in, const char* attribute) const {
  return declared(attachments, in, attribute, "body, mass or anchor", "declared above this element");
}

ThermalNodeRef SceneBuild::thermalNode(ElementReader& in, const char* attribute) const {
  return declared(thermalNodes, in, attribute, "thermal node",
                  "declared above (thermo_spring, thermo_maxwell, reservoir or fixed_temperature)");
}

int SceneBuild::addThermalNode(const std::string& name, int dof, double dofScale) {
  const int node = static_cast<int>(thermalNodeNames.size());
  thermalNodeNames.push_back(name);
  thermalNodes[name] = ThermalNodeRef{node, dof, {}, {}};
  if (dof >= 0) scale[dof] = dofScale;
  return node;
}

void SceneBuild::addThermalNodeOwner(const std::string& node, std::unique_ptr<Component> component) {
  ThermalNodeRef& ref = thermalNodes.at(node);
  ref.ownerDofs = component->dofs();
  ref.ownerVelocity.clear();
  for (int dof : ref.ownerDofs) ref.ownerVelocity.push_back(layout.blockOf(dof) == Block::Velocity);
  addComponent(std::move(component));
}

ConstraintSettings SceneBuild::constraintSettings(ElementReader& in) const {
  ConstraintSettings settings = spec.constraints;
  const std::string enforcement =
      in.text("enforcement", settings.enforcement == Enforcement::Penalty ? "penalty" : "augmented_lagrangian");
  if (enforcement != "penalty" && enforcement != "augmented_lagrangian")
    in.fail("enforcement must be 'penalty' or 'augmented_lagrangian', got '" + enforcement + "'");
  settings.enforcement = enforcement == "penalty" ? Enforcement::Penalty : Enforcement::AugmentedLagrangian;
  settings.stiffness = in.positive("stiffness", settings.stiffness);
  return settings;
}

bool SceneBuild::takesMultipliers(const ElementReader& in) const {
  const std::string* enforcement = in.element().find("enforcement");
  return enforcement ? *enforcement == "augmented_lagrangian"
                     : spec.constraints.enforcement == Enforcement::AugmentedLagrangian;
}

void SceneBuild::addConstraint(const std::string& name, const JointBuilder& builder, std::vector<QuadraticForm> forms,
                               bool leadingGap, const ConstraintSettings& settings, DofRange& dofs) {
  ConstraintSpec constraint;
  constraint.name = name;
  constraint.leadingGap = leadingGap;
  constraint.positionDofs = builder.positionDofs();
  constraint.velocityShift = velocityShift();
  constraint.enforcement = settings.enforcement;
  constraint.stiffness = settings.stiffness;
  // two multipliers per constraint: lambda, and mu of the rate form (GGL)
  if (settings.enforcement == Enforcement::AugmentedLagrangian) {
    const int count = 2 * static_cast<int>(forms.size());
    constraint.firstMultiplierDof = dofs.take(Block::Multiplier, count);
    scale.segment(constraint.firstMultiplierDof, count).setOnes();
  }
  constraint.forms = std::move(forms);
  auto component = std::make_unique<QuadraticConstraint>(std::move(constraint));
  constraints.push_back({component.get(), builder.ends()});
  addComponent(std::move(component));
}

const SolidPlacement& SceneBuild::solidOf(ElementReader& in) const {
  const std::string name = in.text("solid");
  for (const SolidPlacement& solid : solids)
    if (solid.name == name) return solid;
  in.fail("attribute 'solid': no solid named '" + name + "' declared above this element");
}

std::vector<int> SceneBuild::solidNodes(ElementReader& in, const SolidPlacement& solid) const {
  const std::string set = in.text("surface");
  try {
    return solid.mesh->nodesOf(set);
  } catch (const std::out_of_range&) {
    std::string known;
    for (const auto& [name, faces] : solid.mesh->surfaces) known += " " + name;
    for (const auto& [name, nodes] : solid.mesh->nodeSets) known += " " + name;
    in.fail("attribute 'surface': the mesh of '" + solid.name + "' has no surface or node set '" + set +
            "' (it has:" + known + ")");
  }
}

namespace {
std::array<const std::vector<ElementKind>*, 5> elementFamilies() {
  return {&lumpedElementKinds(), &thermalElementKinds(), &multibodyElementKinds(), &solidElementKinds(),
          &thermalSolidElementKinds()};
}
}  // namespace

const ElementKind* findElementKind(const std::string& tag) {
  for (const auto* family : elementFamilies())
    for (const ElementKind& kind : *family)
      if (tag == kind.tag) return &kind;
  return nullptr;
}

std::string elementTags() {
  std::string tags;
  for (const auto* family : elementFamilies())
    for (const ElementKind& kind : *family) tags += (tags.empty() ? "" : ", ") + std::string(kind.tag);
  return tags;
}

std::string fileNameProblem(const std::string& name) {
  constexpr std::size_t kLongest = 64;
  const bool allowed = std::all_of(name.begin(), name.end(), [](unsigned char c) {
    return std::isalnum(c) || c == '_' || c == '-' || c == '.' || c == '+';
  });
  if (name.empty() || name.size() > kLongest || !allowed || name.front() == '.')
    return "'" + echoed(name) + "'" +
           " names output files, so it must be 1 to 64 of A-Z a-z 0-9 _ - . + and not start with '.'";
  return "";
}

namespace {

TimeFunction parseProfile(ElementReader& in) {
  const std::string profile = in.text("profile", "constant");
  if (profile == "constant") return TimeFunction::constant();
  if (profile == "ramp") {
    const double start = in.nonNegative("start", 0.0), end = in.positive("end");
    if (!(end > start)) in.fail("ramp needs end > start");
    return TimeFunction::ramp(start, end);
  }
  if (profile == "hat") return TimeFunction::hat(in.positive("period"));
  if (profile == "sine_pulse") return TimeFunction::sinePulse(in.positive("duration"));
  if (profile == "table") {
    std::vector<double> times = in.numbers("times"), values = in.numbers("values");
    if (times.empty() || times.size() != values.size()) in.fail("'times' and 'values' need the same, non-zero count");
    if (!std::is_sorted(times.begin(), times.end(), std::less_equal<>()) ||
        std::adjacent_find(times.begin(), times.end()) != times.end())
      in.fail("'times' must be strictly increasing");
    return TimeFunction::table(std::move(times), std::move(values));
  }
  in.fail("profile must be constant, ramp, hat, sine_pulse or table, got '" + profile + "'");
}

}  // namespace

TimeFunction readProfile(ElementReader& in, SceneBuild& build) {
  const TimeFunction profile = parseProfile(in);
  const std::vector<double> breakpoints = profile.breakpoints();
  build.loadBreakpoints.insert(build.loadBreakpoints.end(), breakpoints.begin(), breakpoints.end());
  return profile;
}

}  // namespace mpx
