// The state layout a scene compiles to: a block exists only when an element asks for it, and
// each element adds exactly the dofs (and thermal nodes) it owns.
#include "support.hpp"

#include <gtest/gtest.h>

#include <array>
#include <string>

namespace mpx {
namespace {

std::string sceneText(const std::string& body) {
  return R"(<metriplex><simulation dt="0.1" t_end="1"/>)" + body + "</metriplex>";
}

CompiledScene compile(const std::string& body) { return loadSceneText(sceneText(body), "layout-test"); }

std::array<int, kBlockCount> blockSizes(const Layout& layout) {
  std::array<int, kBlockCount> sizes{};
  for (int b = 0; b < kBlockCount; ++b) sizes[b] = layout.size(static_cast<Block>(b));
  return sizes;
}

// n masses hanging from an anchor in a chain of springs, with a damper, a load and gravity:
// every mechanical element kind, none of which owns a thermal or internal dof.
std::string mechanicalBody(int masses) {
  std::string body = R"(<gravity g="0 0 -9.81"/><anchor name="pivot" position="0 0 0"/>)";
  std::string previous = "pivot";
  for (int i = 0; i < masses; ++i) {
    const std::string name = "m" + std::to_string(i), x = std::to_string(i + 1);
    body += R"(<mass name=")" + name + R"(" mass="1" position=")" + x + R"( 0 0"/>)";
    body += R"(<spring name="k)" + name + R"(" a=")" + previous + R"(" b=")" + name +
            R"(" stiffness="10" rest_length="1"/>)";
    previous = name;
  }
  body += R"(<damper name="dashpot" a="pivot" b="m0" coefficient="0.5"/>)";
  body += R"(<force name="push" on="m0" force="0 1 0" profile="ramp" start="0" end="1"/>)";
  return body;
}

// A purely mechanical scene has positions and velocities only: 3 of each per mass, no thermal
// block, no internal block, no thermal node.
TEST(Layout, MechanicalSceneHasOnlyPositionsAndVelocities) {
  for (int masses : {1, 2, 3}) {
    const CompiledScene scene = compile(mechanicalBody(masses));
    const Layout& layout = scene.model->layout();
    EXPECT_EQ(layout.size(Block::Position), 3 * masses);
    EXPECT_EQ(layout.size(Block::Velocity), 3 * masses);
    for (Block absent : {Block::Thermal, Block::Internal, Block::Multiplier}) {
      EXPECT_FALSE(layout.has(absent)) << blockName(absent) << " with " << masses << " masses";
      EXPECT_EQ(layout.size(absent), 0) << blockName(absent) << " with " << masses << " masses";
    }
    EXPECT_EQ(layout.total(), 6 * masses);
    EXPECT_EQ(scene.model->initialState().size(), layout.total());
    EXPECT_TRUE(scene.model->thermalNodeNames().empty());
  }
}

// One element added to a scene that already holds what it refers to, and what it must add.
struct Addition {
  std::string tag;
  std::string prerequisites;  // thermal nodes a heat link needs
  std::string xml;
  int thermalDofs, internalDofs, thermalNodes;
};

const std::string kThermoSpring =
    R"(<thermo_spring name="hot" a="pivot" b="m1" stiffness="1" coupling="0.5" rest_length="1" heat_capacity="1"
                      reference_temperature="1" temperature="1.2"/>)";
const std::string kWall = R"(<fixed_temperature name="wall" temperature="2"/>)";

const Addition kAdditions[] = {
    {"thermo_spring", "", kThermoSpring, 1, 0, 1},
    {"thermo_maxwell", "",
     R"(<thermo_maxwell name="visco" a="m0" b="m1" stiffness="1" coupling="0.5" rest_length="1" heat_capacity="1"
                        reference_temperature="1" branch_stiffness="2" viscosity="1" temperature="1"/>)",
     1, 1, 1},
    {"reservoir", "", R"(<reservoir name="environment" heat_capacity="5" temperature="1"/>)", 1, 0, 1},
    {"maxwell", "",
     R"(<maxwell name="branch" a="m0" b="m1" stiffness="1" rest_length="1" branch_stiffness="2" viscosity="1"/>)", 0, 1,
     0},
    {"fixed_temperature", "", kWall, 0, 0, 1},
    {"heat_link", kThermoSpring + kWall, R"(<heat_link name="conduction" a="hot" b="wall" conductivity="0.5"/>)", 0, 0,
     0},
};

// Each element adds exactly its own dofs: thermo_spring and reservoir one thermal dof and node,
// maxwell one internal dof, thermo_maxwell one of each, fixed_temperature a node without a
// dof, heat_link nothing; positions and velocities never change.
TEST(Layout, EachElementAddsExactlyItsOwnDofs) {
  for (const Addition& addition : kAdditions) {
    const std::string before = mechanicalBody(2) + addition.prerequisites;
    const CompiledScene without = compile(before);
    const CompiledScene with = compile(before + addition.xml);
    std::array<int, kBlockCount> expected = blockSizes(without.model->layout());
    expected[static_cast<int>(Block::Thermal)] += addition.thermalDofs;
    expected[static_cast<int>(Block::Internal)] += addition.internalDofs;
    EXPECT_EQ(blockSizes(with.model->layout()), expected) << addition.tag;
    EXPECT_EQ(with.model->thermalNodeNames().size(), without.model->thermalNodeNames().size() + addition.thermalNodes)
        << addition.tag;
    EXPECT_EQ(with.model->layout().has(Block::Thermal), expected[static_cast<int>(Block::Thermal)] > 0) << addition.tag;
    EXPECT_EQ(with.model->layout().has(Block::Internal), expected[static_cast<int>(Block::Internal)] > 0)
        << addition.tag;
  }
}

// The thermal node of a fixed temperature carries its name, so output columns can be labelled.
TEST(Layout, FixedTemperatureNodeIsNamed) {
  const CompiledScene scene = compile(mechanicalBody(2) + kWall);
  ASSERT_EQ(scene.model->thermalNodeNames().size(), 1u);
  EXPECT_EQ(scene.model->thermalNodeNames().front(), "wall");
  EXPECT_FALSE(scene.model->layout().has(Block::Thermal));
}

}  // namespace
}  // namespace mpx
