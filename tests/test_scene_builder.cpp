// The scene front end: a scene built in code (SceneSpec) compiles to the same model as the
// XML file that says the same, the declarations of every element kind and what its builder
// takes agree (DofRange refuses more and reports less), every registered element is
// documented, and the XML reader rejects what it would otherwise ignore.
#include "support.hpp"

#include "models/scene/xml_scene.hpp"

#include <gtest/gtest.h>

#include <stdexcept>

namespace mpx::test {
namespace {

// The two thermo-spring system of tests/data/two_thermo_springs.xml, written in C++.
SceneSpec twoThermoSpringsInCode() {
  SceneSpec scene;
  scene.name = "two_thermo_springs";
  scene.label = "two springs built in code";
  scene.settings.dt = 0.2;
  scene.settings.tEnd = 200;
  scene.settings.thermalVariable = ThermalVariable::Entropy;
  scene.add("anchor", {{"name", "origin"}, {"position", Vec3(0, 0, 0)}});
  scene.add("mass", {{"name", "m1"}, {"mass", 1.0}, {"position", Vec3(1, 0, 0)}, {"velocity", Vec3(0, 2, 0)}});
  scene.add("mass", {{"name", "m2"}, {"mass", 1.0}, {"position", Vec3(2.2, 0, 0)}, {"velocity", Vec3(1, 0, 0)}});
  for (const auto& [name, a, b, entropy] : {std::tuple{"s1", "origin", "m1", 1.0}, std::tuple{"s2", "m1", "m2", 0.2}})
    scene.add("thermo_spring", {{"name", name},
                                {"a", a},
                                {"b", b},
                                {"stiffness", 1.0},
                                {"coupling", 1.0},
                                {"rest_length", 1.0},
                                {"heat_capacity", 1.0},
                                {"reference_temperature", 1.0},
                                {"entropy", entropy}});
  scene.add("heat_link", {{"name", "h12"}, {"a", "s1"}, {"b", "s2"}, {"conductivity", 1.0}});
  return scene;
}

TEST(SceneBuilder, CodeAndXmlGiveTheSameModelAndTheSameRunBitForBit) {
  const CompiledScene fromXml = loadScene(scenePath("two_thermo_springs.xml"));
  const CompiledScene fromCode = compileScene(twoThermoSpringsInCode());
  const Model &x = *fromXml.model, &c = *fromCode.model;
  for (int b = 0; b < kBlockCount; ++b)
    EXPECT_EQ(x.layout().size(static_cast<Block>(b)), c.layout().size(static_cast<Block>(b)));
  EXPECT_EQ(x.components().size(), c.components().size());
  EXPECT_EQ(x.thermalNodeNames(), c.thermalNodeNames());
  EXPECT_EQ(x.initialState(), c.initialState());
  EXPECT_EQ(x.dofScale(), c.dofScale());
  const History hx = run(x, Scheme::Eem, 0.2, 4.0), hc = run(c, Scheme::Eem, 0.2, 4.0);
  ASSERT_EQ(hx.states.size(), hc.states.size());
  EXPECT_EQ(hx.states.back(), hc.states.back());
}

TEST(SceneBuilder, NumbersSurviveTheTextRoundTrip) {
  for (double value : {0.1, 1.0 / 3.0, 6.02214076e23, -2.5e-308, 4.9e-324})
    EXPECT_EQ(std::strtod(AttributeValue(value).text().c_str(), nullptr), value) << AttributeValue(value).text();
}

TEST(SceneBuilder, ErrorsInCodeBuiltScenesNameTheSceneAndTheElement) {
  SceneSpec scene = twoThermoSpringsInCode();
  scene.elements[1].set("mass", -1.0);
  try {
    compileScene(scene);
    FAIL() << "a negative mass compiled";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("two springs built in code: element 2: <mass name=\"m1\">: attribute 'mass' "
                                         "must be positive"),
              std::string::npos)
        << e.what();
  }
  SceneSpec unknown = twoThermoSpringsInCode();
  unknown.add("sprung", {{"name", "x"}});
  EXPECT_THROW(compileScene(unknown), InputError);
  SceneSpec noStep = twoThermoSpringsInCode();
  noStep.settings.dt = 0.0;
  EXPECT_THROW(compileScene(noStep), InputError);
}

// An element that takes more dofs than it declared, or fewer, is a defect of its builder:
// the compiler stops with a logic error instead of writing into another element's block.
TEST(SceneBuilder, DofRangeRefusesMoreAndReportsLessThanDeclared) {
  const Layout layout({6, 6, 2, 3, 0});
  DofRange range(layout, DofDemand{3, 1, 0, 0}, DofDemand{3, 1, 2, 0});
  EXPECT_EQ(range.take(Block::Position, 3), 3);
  EXPECT_EQ(range.take(Block::Thermal, 1), 12 + 1);
  EXPECT_THROW(range.take(Block::Thermal, 1), std::logic_error);
  EXPECT_THROW(range.checkAllTaken("test"), std::logic_error);  // the internal dofs are missing
  EXPECT_EQ(range.take(Block::Internal, 2), 14);
  EXPECT_NO_THROW(range.checkAllTaken("test"));
  EXPECT_THROW(range.take(Block::Velocity, 1), std::logic_error);
}

// Every element kind of the registry is in docs/scene-format.md, so a new kind cannot land
// undocumented.
TEST(SceneBuilder, EveryRegisteredElementIsDocumented) {
  const std::string format = readFile(std::string(METRIPLEX_SOURCE_DIR) + "/docs/scene-format.md");
  ASSERT_FALSE(format.empty());
  std::string tags = elementTags();
  for (std::size_t start = 0; start < tags.size();) {
    const std::size_t end = std::min(tags.find(", ", start), tags.size());
    const std::string tag = tags.substr(start, end - start);
    // the tag itself, not a longer one it begins (joint in joint_force)
    const bool documented = format.find("<" + tag + ">") != std::string::npos ||
                            format.find("<" + tag + " ") != std::string::npos ||
                            format.find("<" + tag + "/") != std::string::npos;
    EXPECT_TRUE(documented) << "<" << tag << "> is not in docs/scene-format.md";
    start = end + 2;
  }
}

// A thermal node learns its owner's dofs from the element that owns it, not from a component
// that happens to carry its name: a body's generated constraint "b.rigidity" next to a
// thermo-spring named "b.rigidity" left the heat link without its thermal dof.
TEST(SceneBuilder, ThermalNodeOwnersAreNotFoundByName) {
  SceneSpec scene = twoThermoSpringsInCode();
  scene.elements.back().set("b", "b.rigidity");  // the heat link joins s1 and the new spring
  scene.elements.insert(scene.elements.end() - 1, ElementSpec{"thermo_spring",
                                                              {{"name", "b.rigidity"},
                                                               {"a", "m1"},
                                                               {"b", "m2"},
                                                               {"stiffness", "1"},
                                                               {"rest_length", "1"},
                                                               {"heat_capacity", "1"},
                                                               {"reference_temperature", "1"},
                                                               {"entropy", "0.5"}},
                                                              {"code", 0, 0}});
  // the body (and its constraint "b.rigidity") comes after the spring, before the heat link
  scene.elements.insert(
      scene.elements.end() - 1,
      ElementSpec{"body", {{"name", "b"}, {"mass", "1"}, {"inertia", "1 1 1"}, {"position", "0 5 0"}}, {"code", 0, 0}});
  const CompiledScene compiled = compileScene(scene);
  const History h = run(*compiled.model, Scheme::Eem, 0.2, 2.0);
  ASSERT_FALSE(h.summary.failed) << h.summary.failure;
  EXPECT_LT(relativeBalanceDrift(h), 1e-12);
  EXPECT_LT(firstEntropyDecrease(h), 0);
}

TEST(SceneBuilder, XmlElementsThatTakeNoChildrenRejectThem) {
  const std::string text = R"(<metriplex><simulation dt="0.1" t_end="1"/>
<mass name="m" mass="1"><mass name="inner" mass="1"/></mass></metriplex>)";
  try {
    readXmlScene(text, "children.xml");
    FAIL() << "a child element was accepted";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("children.xml:2: <mass name=\"m\">: <mass> takes no child elements"),
              std::string::npos)
        << e.what();
  }
}

// names that become output files cannot leave the output directory: "../x", "/abs", ".hidden"
TEST(SceneBuilder, NamesThatBecomeFilesStayInsideTheOutputDirectory) {
  for (const char* bad : {"../../x", "/tmp/abs", ".hidden", "a/b", ""}) {
    const std::string scene = std::string(R"(<metriplex name=")") + bad + R"(">
<simulation dt="0.1" t_end="1"/><mass name="m" mass="1"/></metriplex>)";
    try {
      compileScene(readXmlScene(scene, "names.xml"));
      FAIL() << "scene name '" << bad << "' was accepted";
    } catch (const InputError& e) {
      EXPECT_NE(std::string(e.what()).find("names.xml:1: scene name '"), std::string::npos) << e.what();
    }
    if (!*bad) continue;  // an empty solid name is refused as a name before it is a file name
    const std::string solid = std::string(R"(<metriplex><simulation dt="0.1" t_end="1"/>
<solid name=")") + bad + R"(" mesh="box" size="1 1 1" cells="1 1 1" young="1" poisson="0.3" density="1"/></metriplex>)";
    try {
      compileScene(readXmlScene(solid, "solid.xml"));
      FAIL() << "solid name '" << bad << "' was accepted";
    } catch (const InputError& e) {
      EXPECT_NE(std::string(e.what()).find("solid.xml:2: <solid name="), std::string::npos) << e.what();
      EXPECT_NE(std::string(e.what()).find("solid name '"), std::string::npos) << e.what();
    }
  }
  // a long name is quoted only in part
  SceneSpec spec;
  spec.name = std::string(5000, 'x') + "/";
  spec.settings.dt = spec.settings.tEnd = 1.0;
  spec.add("mass", {{"name", "m"}, {"mass", 1.0}});
  try {
    compileScene(spec);
    FAIL();
  } catch (const InputError& e) {
    EXPECT_LT(std::string(e.what()).size(), 300u) << e.what();
  }
}

}  // namespace
}  // namespace mpx::test
