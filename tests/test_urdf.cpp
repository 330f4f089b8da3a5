// URDF import: the imported initial state matches kinematics computed here from the URDF data
// alone, a URDF pendulum swings with the analytic compound-pendulum period, every kind of
// invalid URDF is rejected with exit code 2 and a message naming the element, the planar joint
// leaves exactly the in-plane motion free, and the URDF scenes run, conserving energy under EEM.
#include "cli_support.hpp"
#include "models/scene/urdf_scene.hpp"
#include "support.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <map>
#include <sstream>
#include <string>
#include <vector>

namespace mpx::test {
namespace {

namespace fs = std::filesystem;
using Pose = Eigen::Isometry3d;

using namespace cli;

// Numbers with 17 digits, space separated, as URDF and scene attributes.
std::string numbers(std::initializer_list<double> values) {
  std::ostringstream text;
  text.precision(17);
  for (const double v : values) text << (text.tellp() > 0 ? " " : "") << v;
  return text.str();
}
std::string numbers(const Vec3& v) { return numbers({v.x(), v.y(), v.z()}); }

// First position dof of body `name`: its Inertia component's (centre of mass, then directors).
int firstDofOf(const Model& model, const std::string& name) {
  for (const auto& component : model.components())
    if (component->name() == name) return component->dofs()[0];
  ADD_FAILURE() << "no body " << name;
  return 0;
}

Vec3 centreOf(const Model& model, const Eigen::VectorXd& z, const std::string& name) {
  return z.segment<3>(firstDofOf(model, name));
}

// Each test writes its URDFs and scenes into a fresh directory.
class UrdfTest : public CliTest {
 protected:
  fs::path write(const std::string& file, const std::string& text) const {
    const fs::path path = dir_ / file;
    std::ofstream(path) << text;
    return path;
  }
};

// ---------------------------------------------------------------------------------------------
// (a) The initial state against kinematics computed here from the URDF data.

// A link as written into the URDF; mass 0 writes no <inertial>.
struct LinkData {
  std::string name;
  double mass;
  Vec3 centre, centreRpy;               // inertial origin in the link frame
  double ixx, iyy, izz, ixy, ixz, iyz;  // about the centre, in the inertial frame
};

struct JointData {
  std::string name, type, parent, child;
  Vec3 xyz, rpy, axis;
  double position, velocity;
};

// Every URDF joint type, a massless link merged into its parent, a massive fixed link, tilted
// axes and rotated inertial frames, on a fixed root placed away from the origin.
const std::vector<LinkData> kLinks = {
    {"base", 3.0, {0.01, 0.0, 0.05}, {0, 0, 0}, 0.02, 0.025, 0.03, 0.001, 0, 0},
    {"upper", 1.2, {0.2, 0.0, 0.0}, {0.1, 0.2, 0.3}, 0.001, 0.016, 0.0165, 0, 0.0002, 0},
    {"slider", 0.7, {0.0, 0.05, 0.0}, {0, 0, 0}, 0.002, 0.001, 0.0025, 0, 0, 0},
    {"mount", 0.0, {0, 0, 0}, {0, 0, 0}, 0, 0, 0, 0, 0, 0},
    {"wheel", 0.2, {0.0, 0.0, 0.01}, {0, 0.4, 0}, 0.0004, 0.0004, 0.0007, 0, 0, 0},
    {"tool", 0.3, {0.02, 0.0, 0.0}, {0, 0, 0.5}, 0.0003, 0.0004, 0.0005, 0, 0, 0.00001},
    {"plate", 0.5, {0.0, 0.0, -0.02}, {0, 0, 0}, 0.003, 0.003, 0.005, 0, 0, 0},
    {"drone", 0.9, {0.0, 0.0, 0.0}, {0, 0, 0}, 0.01, 0.01, 0.018, 0, 0, 0},
};
const std::vector<JointData> kJoints = {
    // parents before children
    {"shoulder", "revolute", "base", "upper", {0, 0, 0.3}, {0, 0, 0.4}, {0, 1, 1}, 0.5, 1.3},
    {"slide", "prismatic", "upper", "slider", {0.4, 0, 0}, {0.3, 0, 0}, {1, 0, 0}, 0.05, -0.4},
    {"mount_joint", "fixed", "slider", "mount", {0, 0.1, 0}, {0, 0.5, 0}, {1, 0, 0}, 0, 0},
    {"spin", "continuous", "mount", "wheel", {0.05, 0, 0}, {0, 0, 0}, {0, 0, 1}, -0.7, 5.0},
    {"tool_joint", "fixed", "slider", "tool", {0, 0, 0.1}, {0.2, 0, 0}, {1, 0, 0}, 0, 0},
    {"plate_joint", "planar", "upper", "plate", {0, 0, -0.1}, {0, 0, 0}, {0, 0, 1}, 0, 0},
    {"drone_joint", "floating", "base", "drone", {0.5, 0.5, 0.5}, {0, 0, 0}, {1, 0, 0}, 0, 0},
};
const Vec3 kRootPosition(0.1, -0.2, 0.3);
const Eigen::Quaterniond kRootOrientation(0.5, 0.5, -0.5, 0.5);  // unit

bool hasCoordinate(const JointData& j) {
  return j.type == "revolute" || j.type == "continuous" || j.type == "prismatic";
}

// urdfdom requires limits on revolute and prismatic joints (the import ignores them).
const std::string kLimit = "<limit lower=\"-1\" upper=\"1\" effort=\"1\" velocity=\"1\"/>";

std::string robotText() {
  std::string text = "<robot name=\"test_robot\">\n";
  for (const LinkData& l : kLinks) {
    text += "  <link name=\"" + l.name + "\">";
    if (l.mass > 0)
      text += "<inertial><origin xyz=\"" + numbers(l.centre) + "\" rpy=\"" + numbers(l.centreRpy) +
              "\"/><mass value=\"" + numbers({l.mass}) + "\"/><inertia ixx=\"" + numbers({l.ixx}) + "\" iyy=\"" +
              numbers({l.iyy}) + "\" izz=\"" + numbers({l.izz}) + "\" ixy=\"" + numbers({l.ixy}) + "\" ixz=\"" +
              numbers({l.ixz}) + "\" iyz=\"" + numbers({l.iyz}) + "\"/></inertial>";
    text += "</link>\n";
  }
  for (const JointData& j : kJoints)
    text += "  <joint name=\"" + j.name + "\" type=\"" + j.type + "\"><parent link=\"" + j.parent +
            "\"/><child link=\"" + j.child + "\"/><origin xyz=\"" + numbers(j.xyz) + "\" rpy=\"" + numbers(j.rpy) +
            "\"/><axis xyz=\"" + numbers(j.axis) + "\"/>" +
            (j.type == "revolute" || j.type == "prismatic" ? kLimit : "") + "</joint>\n";
  return text + "</robot>\n";
}

// URDF roll-pitch-yaw: about the fixed x, y and z axes, in that order.
Pose originPose(const Vec3& xyz, const Vec3& rpy) {
  Pose pose = Pose::Identity();
  pose.translation() = xyz;
  pose.linear() = (Eigen::AngleAxisd(rpy.z(), Vec3::UnitZ()) * Eigen::AngleAxisd(rpy.y(), Vec3::UnitY()) *
                   Eigen::AngleAxisd(rpy.x(), Vec3::UnitX()))
                      .toRotationMatrix();
  return pose;
}

// World pose of each link's inertial frame with every joint coordinate advanced by s times its rate.
std::map<std::string, Pose> inertialFrames(double s) {
  std::map<std::string, Pose> frames;
  frames["base"] = Pose(Eigen::Translation3d(kRootPosition) * kRootOrientation);
  for (const JointData& j : kJoints) {
    const double q = j.position + s * j.velocity;
    Pose motion = Pose::Identity();
    if (j.type == "revolute" || j.type == "continuous") motion.rotate(Eigen::AngleAxisd(q, j.axis.normalized()));
    if (j.type == "prismatic") motion.translate(q * j.axis.normalized());
    frames[j.child] = frames.at(j.parent) * originPose(j.xyz, j.rpy) * motion;
  }
  for (const LinkData& l : kLinks) frames[l.name] = frames[l.name] * originPose(l.centre, l.centreRpy);
  return frames;
}

// sum 1/2 m v^2 + 1/2 w.I w, with v and w from central differences of the frames along the
// joint rates (not from a velocity recursion like the importer's).
double kineticEnergy() {
  constexpr double h = 1e-6;
  const std::map<std::string, Pose> now = inertialFrames(0), ahead = inertialFrames(h), behind = inertialFrames(-h);
  double energy = 0.0;
  for (const LinkData& l : kLinks) {
    if (l.mass == 0.0) continue;
    const Pose &a = ahead.at(l.name), &b = behind.at(l.name);
    const Eigen::Matrix3d R = now.at(l.name).linear();
    const Vec3 v = (a.translation() - b.translation()) / (2 * h);
    const Eigen::Matrix3d skew = (a.linear() - b.linear()) / (2 * h) * R.transpose();  // dR/dt R^T = [w]x
    const Vec3 w(skew(2, 1), skew(0, 2), skew(1, 0));
    Eigen::Matrix3d inertia;
    inertia << l.ixx, l.ixy, l.ixz, l.ixy, l.iyy, l.iyz, l.ixz, l.iyz, l.izz;
    energy += 0.5 * l.mass * v.squaredNorm() + 0.5 * w.dot(R * inertia * R.transpose() * w);
  }
  return energy;
}

TEST_F(UrdfTest, InitialKineticEnergyAndPositionsMatchIndependentKinematics) {
  write("robot.urdf", robotText());
  const Eigen::Quaterniond& q = kRootOrientation;
  std::string scene =
      "<metriplex name=\"kinetic\">\n  <simulation dt=\"0.01\" t_end=\"1\"/>\n"
      "  <urdf file=\"robot.urdf\" position=\"" +
      numbers(kRootPosition) + "\" orientation=\"" + numbers({q.w(), q.x(), q.y(), q.z()}) + "\">\n";
  for (const JointData& j : kJoints)
    if (hasCoordinate(j))
      scene += "    <initial joint=\"" + j.name + "\" position=\"" + numbers({j.position}) + "\" velocity=\"" +
               numbers({j.velocity}) + "\"/>\n";
  scene += "  </urdf>\n</metriplex>\n";
  const CompiledScene compiled = loadScene(write("scene.xml", scene).string());

  Measures measures;  // no gravity: the energy is kinetic
  compiled.model->measure(compiled.model->initialState(), measures);
  const double expected = kineticEnergy();
  std::printf("kinetic energy: imported %.15g J, from the URDF data %.15g J\n", measures.energy, expected);
  ASSERT_GT(expected, 0.1);
  EXPECT_NEAR(measures.energy, expected, 1e-8 * expected);
  const std::map<std::string, Pose> frames = inertialFrames(0);
  for (const LinkData& l : kLinks) {
    if (l.mass == 0.0) continue;
    const Vec3 centre = centreOf(*compiled.model, compiled.model->initialState(), l.name);
    EXPECT_LT((centre - frames.at(l.name).translation()).norm(), 1e-12) << l.name;
  }
}

// ---------------------------------------------------------------------------------------------
// (b) A single-link URDF pendulum: small-amplitude period against 2 pi sqrt(I_pivot / (m g d)).

TEST_F(UrdfTest, PendulumPeriodMatchesTheCompoundPendulum) {
  // a 0.04 x 0.04 x 0.6 m box of 2 kg hinged about y at its top end, released 1e-3 rad out
  const double m = 2.0, length = 0.6, width = 0.04, d = length / 2, g = 9.81, amplitude = 1e-3, dt = 1e-3;
  const double iyy = m / 12 * (width * width + length * length), izz = m / 6 * width * width;
  write("pendulum.urdf",
        "<robot name=\"pendulum\">\n  <link name=\"world\"/>\n"
        "  <link name=\"rod\"><inertial><origin xyz=\"0 0 " +
            numbers({-d}) + "\"/><mass value=\"" + numbers({m}) + "\"/><inertia ixx=\"" + numbers({iyy}) + "\" iyy=\"" +
            numbers({iyy}) + "\" izz=\"" + numbers({izz}) +
            "\" ixy=\"0\" ixz=\"0\" iyz=\"0\"/></inertial></link>\n"
            "  <joint name=\"hinge\" type=\"continuous\"><parent link=\"world\"/><child link=\"rod\"/>"
            "<axis xyz=\"0 1 0\"/></joint>\n</robot>\n");
  const std::string scene = "<metriplex name=\"pendulum\">\n  <simulation dt=\"" + numbers({dt}) +
                            "\" t_end=\"3\"/>\n  <gravity g=\"0 0 " + numbers({-g}) +
                            "\"/>\n  <urdf file=\"pendulum.urdf\">\n    <initial joint=\"hinge\" position=\"" +
                            numbers({amplitude}) + "\"/>\n  </urdf>\n</metriplex>\n";
  const CompiledScene compiled = loadScene(write("scene.xml", scene).string());
  const History h = run(*compiled.model, Scheme::Eem, dt, 3.0);
  ASSERT_FALSE(h.summary.failed) << h.summary.failure;

  // the angle from the rod's centre (x, z) = d (-sin theta, -cos theta); zero crossings
  // interpolated linearly within their step
  std::vector<double> crossings;
  double previous = amplitude;
  for (std::size_t n = 1; n < h.states.size(); ++n) {
    const Vec3 centre = centreOf(*compiled.model, h.states[n], "rod");
    const double theta = std::atan2(-centre.x(), -centre.z());
    if ((previous > 0) != (theta > 0))
      crossings.push_back(h.time[n - 1] + (h.time[n] - h.time[n - 1]) * previous / (previous - theta));
    previous = theta;
  }
  ASSERT_GE(crossings.size(), 4u);
  const double period = 2 * (crossings[3] - crossings[0]) / 3;
  // with the first amplitude correction theta0^2/16 of the large-amplitude series
  const double analytic = 2 * M_PI * std::sqrt((iyy + m * d * d) / (m * g * d)) * (1 + amplitude * amplitude / 16);
  std::printf("pendulum period: EEM %.10f s, analytic %.10f s, relative error %.3e\n", period, analytic,
              std::abs(period - analytic) / analytic);
  EXPECT_LT(std::abs(period - analytic) / analytic, 1e-4);
}

// ---------------------------------------------------------------------------------------------
// (c) Invalid URDFs: exit code 2 and a message naming the file, line and element.

// A URDF with <robot> on line 1 and one element per line from line 2 on.
std::string robotWith(const std::vector<std::string>& elements) {
  std::string text = "<robot name=\"bad\">\n";
  for (const std::string& e : elements) text += "  " + e + "\n";
  return text + "</robot>\n";
}

std::string linkWith(const std::string& name, const std::string& mass, const std::string& moments) {
  return "<link name=\"" + name + "\"><inertial><mass value=\"" + mass + "\"/><inertia " + moments +
         " ixy=\"0\" ixz=\"0\" iyz=\"0\"/></inertial></link>";
}

std::string jointWith(const std::string& name, const std::string& type, const std::string& parent,
                      const std::string& child, const std::string& inside = "<axis xyz=\"0 1 0\"/>") {
  return "<joint name=\"" + name + "\" type=\"" + type + "\"><parent link=\"" + parent + "\"/><child link=\"" + child +
         "\"/>" + inside + "</joint>";
}

const std::string kWorld = "<link name=\"world\"/>";  // line 2
const std::string kBox = "ixx=\"0.02\" iyy=\"0.02\" izz=\"0.001\"";
const std::string kArm = linkWith("arm", "1", kBox);  // line 3
const std::string kHinge = jointWith("hinge", "continuous", "world", "arm");
const std::string kValidRobot = robotWith({kWorld, kArm, kHinge});

// One invalid URDF run alone: the line its message names (0: urdfdom's message, no line) and
// the words it must contain.
struct BadUrdf {
  std::string label;
  std::string urdf;
  int line;
  std::vector<std::string> mentions;
};

std::ostream& operator<<(std::ostream& os, const BadUrdf& c) { return os << c.label; }

const std::vector<BadUrdf> kBadUrdfs = {
    {"MalformedXml", "<robot name=\"bad\">\n  <link name=\"world\">\n</robot>\n", 2, {"malformed XML", "link"}},
    {"UndeclaredEntity", "<robot name=\"bad\">\n  <link name=\"w&x;\"/>\n</robot>\n", 2, {"undefined entity", "&x;"}},
    {"SecondRoot",
     "<robot name=\"a\">\n  <link name=\"world\"/>\n</robot>\n<robot name=\"b\"/>\n",
     4,
     {"second root element", "<robot>"}},
    {"RevoluteWithoutLimits",
     robotWith({kWorld, kArm, jointWith("hinge", "revolute", "world", "arm")}),
     0,
     {"invalid URDF", "[hinge]", "limits"}},
    {"UnparsableMass",
     robotWith({kWorld, linkWith("arm", "heavy", kBox), kHinge}),
     0,
     {"invalid URDF", "[heavy]", "[arm]"}},
    {"MissingLink",
     robotWith({kWorld, kArm, kHinge, jointWith("wrist", "continuous", "arm", "hand")}),
     0,
     {"invalid URDF", "[hand]", "[wrist]"}},
    {"TwoRoots",
     robotWith({kWorld, kArm, linkWith("loose", "1", kBox), kHinge}),
     0,
     {"invalid URDF", "Two root links", "[loose]"}},
    {"CycleAwayFromTheRoot",
     robotWith({kWorld, kArm, linkWith("a", "1", kBox), linkWith("b", "1", kBox), kHinge,
                jointWith("ab", "continuous", "a", "b"), jointWith("ba", "continuous", "b", "a")}),
     4,
     {"<link name=\"a\">", "on a cycle of joints", "'ba'"}},
    {"LinkWithTwoParents",
     robotWith({kWorld, kArm, linkWith("b", "1", kBox), kHinge, jointWith("world_b", "continuous", "world", "b"),
                jointWith("arm_b", "continuous", "arm", "b")}),
     4,
     {"<link name=\"b\">", "child of two joints", "'world_b'", "'arm_b'"}},
    {"NegativeMass",
     robotWith({kWorld, linkWith("arm", "-1", kBox), kHinge}),
     3,
     {"<link name=\"arm\">", "mass must be positive"}},
    {"ZeroMassMovingLink",
     robotWith({kWorld, "<link name=\"arm\"/>", kHinge}),
     3,
     {"<link name=\"arm\">", "has no mass", "'hinge'"}},
    {"ZeroMassWithInertia",
     robotWith({kWorld, linkWith("arm", "0", kBox), kHinge}),
     3,
     {"<link name=\"arm\">", "mass must be positive"}},
    {"IndefiniteInertia",
     robotWith({kWorld, linkWith("arm", "1", "ixx=\"0.02\" iyy=\"-0.02\" izz=\"0.001\""), kHinge}),
     3,
     {"<link name=\"arm\">", "positive definite"}},
    {"FlatInertia",
     robotWith({kWorld, linkWith("arm", "1", "ixx=\"0.01\" iyy=\"0.01\" izz=\"0.03\""), kHinge}),
     3,
     {"<link name=\"arm\">", "triangle inequality", "balance_inertia"}},
    {"Mimic",
     robotWith({kWorld, kArm, linkWith("hand", "1", kBox), kHinge,
                jointWith("wrist", "continuous", "arm", "hand", "<axis xyz=\"0 1 0\"/><mimic joint=\"hinge\"/>")}),
     6,
     {"<joint name=\"wrist\">", "mimic"}},
    {"JointNamedLikeALink",
     robotWith({kWorld, kArm, jointWith("arm", "continuous", "world", "arm")}),
     4,
     {"<joint name=\"arm\">", "name of a link"}},
    {"ZeroAxis",
     robotWith({kWorld, kArm, jointWith("hinge", "continuous", "world", "arm", "<axis xyz=\"0 0 0\"/>")}),
     4,
     {"<joint name=\"hinge\">", "<axis>"}},
};

class BadUrdfTest : public UrdfTest, public ::testing::WithParamInterface<BadUrdf> {};

TEST_P(BadUrdfTest, RunExitsTwoNamingTheFileAndElement) {
  const BadUrdf& c = GetParam();
  const fs::path urdf = write("bad.urdf", c.urdf);
  const Invocation r = metriplex("run " + quoted(urdf) + " --out " + quoted(dir_ / "out"));
  EXPECT_EQ(r.exitCode, kExitInvalidInput) << r.err;
  const std::string where = urdf.string() + ":" + (c.line > 0 ? std::to_string(c.line) + ":" : "");
  EXPECT_NE(r.err.find(where), std::string::npos) << r.err;
  for (const std::string& mention : c.mentions) EXPECT_NE(r.err.find(mention), std::string::npos) << r.err;
  EXPECT_FALSE(fs::exists(dir_ / "out"));
}

INSTANTIATE_TEST_SUITE_P(Urdf, BadUrdfTest, ::testing::ValuesIn(kBadUrdfs),
                         [](const ::testing::TestParamInfo<BadUrdf>& info) { return info.param.label; });

// One invalid <urdf> inclusion: the URDF, the scene's elements from line 5 on (a <urdf> on
// line 5), and the words the message must contain after "scene.xml:5:".
struct BadInclude {
  std::string label;
  std::string urdf;
  std::string elements;
  std::vector<std::string> mentions;
};

std::ostream& operator<<(std::ostream& os, const BadInclude& c) { return os << c.label; }

const std::vector<BadInclude> kBadIncludes = {
    {"InvalidUrdfNamesBothFiles",
     robotWith({kWorld, linkWith("arm", "-1", kBox), kHinge}),
     "<urdf file=\"robot.urdf\"/>",
     {"<urdf>", "robot.urdf:3:", "<link name=\"arm\">", "mass must be positive"}},
    {"MissingUrdfFile", kValidRobot, "<urdf file=\"no_such.urdf\"/>", {"<urdf>", "no_such.urdf", "cannot open"}},
    {"UnknownInitialJoint",
     kValidRobot,
     "<urdf file=\"robot.urdf\"><initial joint=\"elbow\" position=\"1\"/></urdf>",
     {"<urdf>", "'elbow'", "does not have"}},
    {"InitialOnFixedJoint",
     robotWith({kWorld, kArm, jointWith("weld", "fixed", "world", "arm", "")}),
     "<urdf file=\"robot.urdf\"><initial joint=\"weld\" position=\"1\"/></urdf>",
     {"<urdf>", "<joint name=\"weld\">", "no initial position"}},
    {"FloatingMasslessRoot",
     kValidRobot,
     "<urdf file=\"robot.urdf\" floating=\"true\"/>",
     {"<urdf>", "<link name=\"world\">", "floating root"}},
    {"BadFlag", kValidRobot, "<urdf file=\"robot.urdf\" floating=\"yes\"/>", {"<urdf>", "'floating'", "'yes'"}},
    {"NameClash",
     kValidRobot,
     "<urdf file=\"robot.urdf\"/>\n  <mass name=\"arm\" mass=\"1\"/>",
     {"<urdf>", "'arm'", "line 6", "prefix"}},
};

class BadIncludeTest : public UrdfTest, public ::testing::WithParamInterface<BadInclude> {};

TEST_P(BadIncludeTest, RunExitsTwoAtTheUrdfElement) {
  const BadInclude& c = GetParam();
  write("robot.urdf", c.urdf);
  const fs::path scene = write("scene.xml",
                               "<?xml version=\"1.0\"?>\n<metriplex name=\"include\">\n"
                               "  <simulation dt=\"0.01\" t_end=\"0.1\"/>\n"
                               "  <anchor name=\"pivot\"/>\n  " +
                                   c.elements + "\n</metriplex>\n");
  const Invocation r = metriplex("run " + quoted(scene) + " --out " + quoted(dir_ / "out"));
  EXPECT_EQ(r.exitCode, kExitInvalidInput) << r.err;
  EXPECT_NE(r.err.find(scene.string() + ":5:"), std::string::npos) << r.err;
  for (const std::string& mention : c.mentions) EXPECT_NE(r.err.find(mention), std::string::npos) << r.err;
  EXPECT_FALSE(fs::exists(dir_ / "out"));
}

INSTANTIATE_TEST_SUITE_P(Urdf, BadIncludeTest, ::testing::ValuesIn(kBadIncludes),
                         [](const ::testing::TestParamInfo<BadInclude>& info) { return info.param.label; });

// ---------------------------------------------------------------------------------------------
// The planar joint: a body on the ground's z = 1 plane keeps its height and its normal, and
// moves freely in the plane (constant velocity and spin) while gravity presses it down.

TEST(PlanarJoint, LeavesExactlyTheInPlaneMotionFree) {
  const Vec3 start(0.2, -0.1, 1.0), velocity(0.8, 0.3, 0.0);
  const double spin = 2.0, dt = 0.01, tEnd = 2.0;
  const CompiledScene compiled = loadSceneText(
      "<metriplex name=\"planar\">\n  <simulation dt=\"0.01\" t_end=\"2\"/>\n  <gravity g=\"0 0 -9.81\"/>\n"
      "  <anchor name=\"ground\"/>\n"
      "  <body name=\"puck\" mass=\"2\" inertia=\"0.01 0.012 0.02\" position=\"" +
          numbers(start) + "\" velocity=\"" + numbers(velocity) + "\" angular_velocity=\"0 0 " + numbers({spin}) +
          "\"/>\n"
          "  <joint name=\"table\" type=\"planar\" a=\"ground\" b=\"puck\" anchor=\"0 0 1\" axis=\"0 0 1\"/>\n"
          "</metriplex>\n",
      "planar-test");
  const History h = run(*compiled.model, Scheme::Eem, dt, tEnd);
  ASSERT_FALSE(h.summary.failed) << h.summary.failure;
  const Vec3 end = centreOf(*compiled.model, h.states.back(), "puck");
  EXPECT_LT((end - (start + tEnd * velocity)).norm(), 1e-8) << end.transpose();
  // the director along the normal (smallest "mass" E_3: largest moment) stays vertical
  const int first = firstDofOf(*compiled.model, "puck");
  Vec3 normalDirector = Vec3::Zero();
  for (int i = 0; i < 3; ++i) {
    const Vec3 d = h.states.back().segment<3>(first + 3 + 3 * i);
    if (std::abs(d.z()) > std::abs(normalDirector.z())) normalDirector = d;
  }
  EXPECT_NEAR(std::abs(normalDirector.z()), 1.0, 1e-10);
  EXPECT_LT(h.summary.maxEnergyBalanceError, 1e-10);
  // the spin about the normal is free: the angular momentum about the centre keeps its normal
  // component I_zz spin at every step (a joint that locked the turn would take it to zero, or
  // flip it from step to step)
  double spinDrift = 0.0;
  for (std::size_t n = 0; n < h.states.size(); ++n) {
    const Vec3 centre = centreOf(*compiled.model, h.states[n], "puck");
    const double spinMomentum = (h.angularMomentum[n] - centre.cross(h.momentum[n])).z();
    spinDrift = std::max(spinDrift, std::abs(spinMomentum - 0.02 * spin));
  }
  EXPECT_LT(spinDrift, 1e-10 * 0.02 * spin);
}

// ---------------------------------------------------------------------------------------------
// (d) The URDF scenes run; EEM keeps the energy to round-off, net of what the URDF's joint
// damping dissipates.

TEST(UrdfScenes, IncludedChainConservesEnergyUnderEem) {
  const CompiledScene compiled = loadScene(scenePath("n_link_chain.xml"));
  const double dt = compiled.settings.dt;
  const History h = run(*compiled.model, Scheme::Eem, dt, 300 * dt, compiled.settings.newton);
  ASSERT_FALSE(h.summary.failed) << h.summary.failure;
  ASSERT_EQ(h.summary.steps, 300);
  std::printf("n_link_chain: 300 EEM steps, max |E - E0|/ largest energy = %.3e (E0 = %.6f J)\n",
              h.summary.maxEnergyBalanceError, h.energy.front());
  EXPECT_LT(h.summary.maxEnergyBalanceError, 1e-10);
}

TEST(UrdfScenes, DampedArmBalancesEnergyAndDissipation) {
  const CompiledScene compiled = loadScene(scenePath("damped_robot_arm.xml"));
  const double dt = compiled.settings.dt;
  const History h = run(*compiled.model, Scheme::Eem, dt, 200 * dt, compiled.settings.newton);
  ASSERT_FALSE(h.summary.failed) << h.summary.failure;
  std::printf("damped_robot_arm: 200 EEM steps, dissipated %.6f J, max |E + D - E0|/ largest energy = %.3e\n",
              h.dissipated.back(), h.summary.maxEnergyBalanceError);
  EXPECT_GT(h.dissipated.back(), 0.01 * std::abs(h.energy.front()));  // the URDF damping acts
  EXPECT_LT(h.summary.maxEnergyBalanceError, 1e-10);
}

// A chain deeper than a recursive walk's call stack (one 8 MB stack held about 15 000 links)
// imports in tree order: each link's body and joint right after its parent's.
TEST_F(UrdfTest, ChainOfThirtyThousandLinksImportsParentsFirst) {
  constexpr int kLinks = 30000;
  std::vector<std::string> elements{kWorld};
  for (int i = 1; i <= kLinks; ++i) {
    const std::string name = "l" + std::to_string(i), parent = i == 1 ? "world" : "l" + std::to_string(i - 1);
    elements.push_back(linkWith(name, "1", kBox));
    elements.push_back(jointWith("j" + std::to_string(i), "continuous", parent, name));
  }
  const SceneSpec scene = readUrdfScene(write("deep.urdf", robotWith(elements)).string());
  ASSERT_EQ(scene.elements.size(), 1u + 2u * kLinks) << "the world anchor, then a body and a joint per link";
  for (int i = 1; i <= kLinks; i += 997) {
    const ElementSpec& body = scene.elements[2 * i - 1];
    const ElementSpec& joint = scene.elements[2 * i];
    ASSERT_EQ(body.tag, "body");
    EXPECT_EQ(*body.find("name"), "l" + std::to_string(i));
    ASSERT_EQ(joint.tag, "joint");
    EXPECT_EQ(*joint.find("b"), "l" + std::to_string(i));
  }
}

// A branching tree is walked depth first: a link's whole subtree before its next sibling (world's
// joints j1 -> a and j2 -> b in name order, a's joint j3 -> c), as the recursive walk did.
TEST_F(UrdfTest, BranchesImportDepthFirst) {
  const SceneSpec scene =
      readUrdfScene(write("tree.urdf", robotWith({kWorld, linkWith("a", "1", kBox), linkWith("b", "1", kBox),
                                                  linkWith("c", "1", kBox), jointWith("j1", "continuous", "world", "a"),
                                                  jointWith("j2", "continuous", "world", "b"),
                                                  jointWith("j3", "continuous", "a", "c")}))
                        .string());
  std::vector<std::string> bodies;
  for (const ElementSpec& element : scene.elements)
    if (element.tag == "body") bodies.push_back(*element.find("name"));
  EXPECT_EQ(bodies, (std::vector<std::string>{"a", "c", "b"}));
}

// (with the text of <gazebo> and <transmission> elements, which the importer ignores)
TEST_F(UrdfTest, UrdfFileRunsAsASceneWithDefaults) {
  const fs::path urdf =
      write("robot.urdf",
            robotWith({kWorld, kArm, kHinge, "<gazebo reference=\"arm\"><material>Gazebo/Blue</material></gazebo>",
                       "<transmission name=\"t\"><type>transmission_interface/SimpleTransmission</type>"
                       "</transmission>"}));
  const Invocation r = metriplex("run " + quoted(urdf) + " --t-end 0.01 --out " + quoted(dir_ / "out"));
  ASSERT_EQ(r.exitCode, kExitSuccess) << r.err;
  const std::string history = readFile(dir_ / "out" / "history.csv");
  EXPECT_EQ(std::count(history.begin(), history.end(), '\n'), 1 + 10 + 1) << "header, t = 0 and 10 steps of 1e-3 s";
}

// ---------------------------------------------------------------------------------------------
// (e) Joint stops at the URDF limits, balanced inertias, and visual and collision meshes.

// A 2 kg, 0.6 m rod hinged about y at its top end with limits [-0.5, 0.5] rad, swung into the
// upper limit at 5 rad/s from 0.3 rad in gravity.
const std::string kLimitedPendulum =
    "<robot name=\"limited\">\n  <link name=\"world\"/>\n"
    "  <link name=\"rod\"><inertial><origin xyz=\"0 0 -0.3\"/><mass value=\"2\"/>"
    "<inertia ixx=\"0.0603\" iyy=\"0.0603\" izz=\"0.0005\" ixy=\"0\" ixz=\"0\" iyz=\"0\"/></inertial></link>\n"
    "  <joint name=\"hinge\" type=\"revolute\"><parent link=\"world\"/><child link=\"rod\"/><axis xyz=\"0 1 0\"/>"
    "<limit lower=\"-0.5\" upper=\"0.5\" effort=\"10\" velocity=\"10\"/></joint>\n</robot>\n";

std::string limitedPendulumScene(const std::string& urdfAttributes) {
  return "<metriplex name=\"limited\">\n  <simulation dt=\"0.001\" t_end=\"1\"/>\n  <gravity g=\"0 0 -9.81\"/>\n"
         "  <urdf file=\"limited.urdf\"" +
         urdfAttributes +
         ">\n    <initial joint=\"hinge\" position=\"0.3\" velocity=\"5\"/>\n  </urdf>\n</metriplex>\n";
}

// The stop holds the rod near its limit (the free swing would reach about 1.6 rad), the damped
// stop dissipates, and EEM keeps E + dissipated to round-off.
TEST_F(UrdfTest, JointStopsHoldTheLimitAndBalanceTheEnergy) {
  write("limited.urdf", kLimitedPendulum);
  for (const char* damping : {"0", "5000"}) {
    SCOPED_TRACE(std::string("limit_damping ") + damping);
    const CompiledScene compiled = loadScene(
        write("scene.xml", limitedPendulumScene(std::string(" limits=\"true\" limit_damping=\"") + damping + "\""))
            .string());
    const History h = run(*compiled.model, Scheme::Eem, 1e-3, 1.0, compiled.settings.newton);
    ASSERT_FALSE(h.summary.failed) << h.summary.failure;
    double largest = -1.0;
    for (const Eigen::VectorXd& z : h.states) {
      const Vec3 centre = centreOf(*compiled.model, z, "rod");
      largest = std::max(largest, std::atan2(-centre.x(), -centre.z()));
    }
    std::printf(
        "stopped pendulum (limit_damping %s): largest angle %.4f rad (limit 0.5), dissipated %.4f J, "
        "balance error %.2e\n",
        damping, largest, h.dissipated.back(), h.summary.maxEnergyBalanceError);
    EXPECT_GT(largest, 0.5);
    EXPECT_LT(largest, 0.6);
    EXPECT_LT(h.summary.maxEnergyBalanceError, 1e-10);
    EXPECT_EQ(firstEntropyDecrease(h), -1);
    if (std::string(damping) != "0") {
      EXPECT_GT(h.dissipated.back(), 0.1);
    }
  }
}

// The warning about ignored limits goes with limits="true".
TEST_F(UrdfTest, IgnoredLimitsWarnOnlyWithoutStops) {
  write("limited.urdf", kLimitedPendulum);
  const std::string run = " --t-end 0.01 --out " + quoted(dir_ / "out");
  const Invocation without = metriplex("run " + quoted(write("scene.xml", limitedPendulumScene(""))) + run);
  ASSERT_EQ(without.exitCode, kExitSuccess) << without.err;
  EXPECT_NE(without.err.find("position limits of joints 'hinge' are ignored"), std::string::npos) << without.err;
  const Invocation with =
      metriplex("run " + quoted(write("scene.xml", limitedPendulumScene(" limits=\"true\""))) + run);
  ASSERT_EQ(with.exitCode, kExitSuccess) << with.err;
  EXPECT_EQ(with.err.find("warning"), std::string::npos) << with.err;
  // a .urdf run directly takes them from the command line: the stops are an element of the
  // budget, and there is no warning
  const Invocation direct = metriplex("run " + quoted(dir_ / "limited.urdf") + " --urdf-limits --budget" + run);
  ASSERT_EQ(direct.exitCode, kExitSuccess) << direct.err;
  EXPECT_EQ(direct.err.find("warning"), std::string::npos) << direct.err;
  EXPECT_NE(readFile(dir_ / "out" / "budget.csv").find(",hinge.limits,"), std::string::npos);
  const Invocation xml =
      metriplex("run " + quoted(write("scene.xml", limitedPendulumScene(""))) + " --urdf-limits" + run);
  EXPECT_EQ(xml.exitCode, kExitInvalidInput);
  EXPECT_NE(xml.err.find("only for a .urdf scene"), std::string::npos) << xml.err;
}

// A flat disk's moments 0.01 0.01 0.03 break J_3 < J_1 + J_2: balance_inertia raises the two
// smaller ones to (1.01 J_3)/2 each and says so; without it the URDF is rejected.
TEST_F(UrdfTest, BalanceInertiaRaisesTheSmallerMoments) {
  write("disk.urdf", robotWith({kWorld, linkWith("arm", "1", "ixx=\"0.01\" iyy=\"0.01\" izz=\"0.03\""), kHinge}));
  const std::string run = " --t-end 0.01 --out " + quoted(dir_ / "out");
  const Invocation rejected = metriplex("run " +
                                        quoted(write("scene.xml",
                                                     "<metriplex>\n  <simulation dt=\"0.001\" t_end=\"1\"/>\n  <urdf "
                                                     "file=\"disk.urdf\"/>\n</metriplex>\n")) +
                                        run);
  EXPECT_EQ(rejected.exitCode, kExitInvalidInput);
  EXPECT_NE(rejected.err.find("triangle inequality"), std::string::npos) << rejected.err;
  const Invocation balanced = metriplex("run " +
                                        quoted(write("scene.xml",
                                                     "<metriplex>\n  <simulation dt=\"0.001\" t_end=\"1\"/>\n  <urdf "
                                                     "file=\"disk.urdf\" balance_inertia=\"true\"/>\n</metriplex>\n")) +
                                        run);
  ASSERT_EQ(balanced.exitCode, kExitSuccess) << balanced.err;
  EXPECT_NE(balanced.err.find("link 'arm': principal moments 0.01 0.01 0.03"), std::string::npos) << balanced.err;
  EXPECT_NE(balanced.err.find("raised them to 0.01515 0.01515 0.03"), std::string::npos) << balanced.err;
}

// Visual and collision geometry, meshes with package:// references included, is not physics:
// the import ignores it without a word.
TEST_F(UrdfTest, MeshesAndPackageReferencesAreIgnoredQuietly) {
  const std::string geometry = "<geometry><mesh filename=\"package://foo/meshes/bar.stl\" scale=\"1 1 1\"/></geometry>";
  const std::string arm = "<link name=\"arm\"><inertial><mass value=\"1\"/><inertia " + kBox +
                          " ixy=\"0\" ixz=\"0\" iyz=\"0\"/></inertial><visual><origin xyz=\"0 0 0.1\"/>" + geometry +
                          "<material name=\"blue\"><color rgba=\"0 0 1 1\"/></material></visual><collision>" +
                          geometry +
                          "</collision><collision><geometry><box size=\"0.1 0.1 0.2\"/></geometry>"
                          "</collision></link>";
  const fs::path urdf = write("meshes.urdf", robotWith({kWorld, arm, kHinge}));
  const Invocation r = metriplex("run " + quoted(urdf) + " --t-end 0.01 --out " + quoted(dir_ / "out"));
  ASSERT_EQ(r.exitCode, kExitSuccess) << r.err;
  EXPECT_EQ(r.err, "");
  EXPECT_EQ(readFile(dir_ / "out" / "history.csv"), [&] {
    const fs::path plain = write("plain.urdf", kValidRobot);
    metriplex("run " + quoted(plain) + " --t-end 0.01 --out " + quoted(dir_ / "plain"));
    return readFile(dir_ / "plain" / "history.csv");
  }()) << "the geometry changes nothing";
}

}  // namespace
}  // namespace mpx::test
