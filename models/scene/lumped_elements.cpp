// Point masses, anchors, two-point force elements and point loads (docs/scene-format.md).
#include "models/lumped/actuator.hpp"
#include "models/lumped/damper.hpp"
#include "models/lumped/element_laws.hpp"
#include "models/lumped/external_force.hpp"
#include "models/lumped/lumped_element.hpp"
#include "models/multibody/inertia.hpp"
#include "models/scene/scene_build.hpp"

namespace mpx {

namespace {

void buildMass(ElementReader& in, SceneBuild& build, DofRange& dofs) {
  const std::string name = build.declareName(in);
  const double mass = in.positive("mass");
  const int position = dofs.take(Block::Position, 3);
  const Endpoint end = Endpoint::point(position, position + build.velocityShift());
  build.state.segment<3>(end.positionDof) = in.vector("position", Vec3::Zero());
  build.state.segment<3>(end.velocityDof) = in.vector("velocity", Vec3::Zero());
  build.keepPositionScale(build.state.segment<3>(end.positionDof).norm());
  build.points[name] = end;
  build.attachments[name] =
      Attachment{Attachment::Kind::Point, end.positionDof, build.state.segment<3>(end.positionDof), Mat3::Identity()};
  build.addComponent(std::make_unique<Inertia>(name, end.positionDof, end.velocityDof,
                                               std::vector<InertiaBlock>{{mass, true}}, build.spec.gravity));
}

void buildAnchor(ElementReader& in, SceneBuild& build, DofRange&) {
  const std::string name = build.declareName(in);
  const Endpoint end = Endpoint::fixed(in.vector("position", Vec3::Zero()));
  build.keepPositionScale(end.anchor.norm());
  build.points[name] = end;
  build.attachments[name] = Attachment{Attachment::Kind::Ground, -1, end.anchor, Mat3::Identity()};
}

// <spring> and <maxwell>: Hooke's law in the stretch, with a Maxwell branch for the latter.
void buildHookeElement(ElementReader& in, SceneBuild& build, DofRange& dofs, bool withBranch) {
  LumpedElementSpec spec;
  spec.name = build.declareName(in);
  spec.ends = build.endpoints(in);
  spec.form = build.spec.settings.discreteGradient;
  const double stiffness = in.nonNegative("stiffness", 0.0);
  const double restLength = in.positive("rest_length");
  double branchStiffness = 0.0;
  if (withBranch) {
    branchStiffness = in.positive("branch_stiffness");
    spec.viscosity.reference = in.positive("viscosity");
    spec.internalDof = dofs.take(Block::Internal, 1);
    build.state[spec.internalDof] = in.number("viscous_elongation", 0.0);
    build.scale[spec.internalDof] = restLength;
  }
  if (!withBranch && !(stiffness > 0.0)) in.fail("attribute 'stiffness' must be positive");
  build.keepPositionScale(restLength);
  spec.law = std::make_shared<HookeLaw>(stiffness, restLength, branchStiffness);
  spec.argumentScale = Vec3(restLength * restLength, 1.0, restLength);
  build.addComponent(std::make_unique<LumpedElement>(std::move(spec)));
}

void buildDamper(ElementReader& in, SceneBuild& build, DofRange&) {
  const std::string name = build.declareName(in);
  const auto [a, b] = build.endpoints(in);
  build.addComponent(std::make_unique<Damper>(name, a, b, in.positive("coefficient")));
}

void buildActuator(ElementReader& in, SceneBuild& build, DofRange&) {
  const std::string name = build.declareName(in);
  const auto [a, b] = build.endpoints(in);
  const double force = in.number("force");
  build.addComponent(std::make_unique<Actuator>(name, a, b, force, readProfile(in, build)));
}

void buildForce(ElementReader& in, SceneBuild& build, DofRange&) {
  const std::string name = build.declareName(in);
  const Endpoint on = build.endpoint(in, "on");
  if (!on.moves()) in.fail("attribute 'on' must name a mass or a body (its centre of mass), not an anchor");
  const Vec3 force = in.vector("force", Vec3::Zero());
  build.addComponent(
      std::make_unique<ExternalForce>(name, on.positionDof, on.velocityDof, force, readProfile(in, build)));
}

}  // namespace

const std::vector<ElementKind>& lumpedElementKinds() {
  static const std::vector<ElementKind> kinds = {
      {"mass",
       [](ElementReader&, SceneBuild&) {
         return DofDemand{3, 0, 0, 0};
       },
       buildMass},
      {"anchor", nullptr, buildAnchor},
      {"spring", nullptr, [](ElementReader& in, SceneBuild& b, DofRange& d) { buildHookeElement(in, b, d, false); }},
      {"maxwell",
       [](ElementReader&, SceneBuild&) {
         return DofDemand{0, 0, 1, 0};
       },
       [](ElementReader& in, SceneBuild& b, DofRange& d) { buildHookeElement(in, b, d, true); }},
      {"damper", nullptr, buildDamper},
      {"actuator", nullptr, buildActuator},
      {"force", nullptr, buildForce},
  };
  return kinds;
}

}  // namespace mpx
