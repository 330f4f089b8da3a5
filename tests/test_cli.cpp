// End-to-end tests of the metriplex command line: exit codes, error messages that point at the
// offending file, line, element and attribute, no output directory on invalid input, and
// DIR/history.csv on success and on a solver failure.
#include "cli_support.hpp"
#include "support.hpp"

#include <gtest/gtest.h>

#include <sys/wait.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

namespace {

namespace fs = std::filesystem;
using namespace mpx::test::cli;
using mpx::test::readFile;

// `text` with its first `from` replaced by `to`: a valid scene with one defect.
std::string replaced(std::string text, const std::string& from, const std::string& to) {
  return text.replace(text.find(from), from.size(), to);
}

// A scene with <simulation> on line 3, an anchor "pivot" on line 4 and `elements` from line 5
// on, so each bad-input case knows the line its message must name.
std::string sceneWith(const std::string& elements) {
  return "<?xml version=\"1.0\"?>\n"
         "<metriplex name=\"cli\">\n"
         "  <simulation dt=\"0.125\" t_end=\"1\"/>\n"
         "  <anchor name=\"pivot\" position=\"0 0 0\"/>\n" +
         elements + "\n</metriplex>\n";
}

// A valid, thermal scene: a mass swinging on a thermo-spring with a temperature-dependent,
// non-linear stiffness (fine for eem, rejected by eem-entropy), heated through a wall.
const std::string kSwingElements =
    "  <mass name=\"bob\" mass=\"1\" position=\"1.2 0 0\" velocity=\"0 1 0\"/>\n"
    "  <thermo_spring name=\"spring\" a=\"pivot\" b=\"bob\" stiffness=\"1\" stiffness_slope=\"-0.2\"\n"
    "                 stiffness_curvature=\"0.05\" coupling=\"0.5\" rest_length=\"1\" heat_capacity=\"1\"\n"
    "                 reference_temperature=\"1\" temperature=\"1\"/>\n"
    "  <fixed_temperature name=\"wall\" temperature=\"2\"/>\n"
    "  <heat_link name=\"to_wall\" a=\"spring\" b=\"wall\" conductivity=\"0.2\"/>";
const std::string kSwingScene = sceneWith(kSwingElements);
constexpr int kSwingSteps = 8;  // t_end / dt

// One invalid scene: its text, extra options, the line its message must name and the words
// (element, attribute, what is wrong) the message must contain.
struct BadScene {
  std::string label;
  std::string xml;
  std::string options;
  int line;
  std::vector<std::string> mentions;
};

// Test names come from the labels.
std::ostream& operator<<(std::ostream& os, const BadScene& c) { return os << c.label; }

const std::vector<BadScene> kBadScenes = {
    {"MalformedXml",
     "<?xml version=\"1.0\"?>\n<metriplex name=\"cli\">\n  <simulation dt=\"0.1\" t_end=\"1\"/>\n"
     "  <mass name=\"bob\" mass=\"1\">\n</metriplex>\n",
     "",
     4,
     {"malformed XML", "mass"}},
    // what tinyxml2 accepts but XML 1.0 does not (models/scene/strict_xml.hpp)
    {"UndeclaredEntity",
     sceneWith("  <anchor name=\"p&foo;\" position=\"0 0 0\"/>"),
     "",
     5,
     {"undefined entity", "&foo;"}},
    {"InvalidCharacterReference",
     sceneWith("  <!-- a\n  comment -->\n  <anchor name=\"p&#1;\" position=\"0 0 0\"/>"),
     "",
     7,
     {"invalid character reference", "&#1;"}},
    {"LessThanInAttribute",
     sceneWith("  <anchor name=\"p<q\" position=\"0 0 0\"/>"),
     "",
     5,
     {"'<' inside an attribute"}},
    {"DocumentTypeDeclaration",
     "<?xml version=\"1.0\"?>\n<!DOCTYPE metriplex [<!ENTITY g \"9.81\">]>\n<metriplex name=\"cli\"/>\n",
     "",
     2,
     {"document type declarations"}},
    {"SecondRootElement",
     sceneWith("") + "<metriplex name=\"again\"/>\n",
     "",
     7,
     {"second root element", "<metriplex>"}},
    {"SecondSolver",
     sceneWith("  <solver max_iterations=\"5\"/>\n  <solver max_iterations=\"7\"/>"),
     "",
     6,
     {"at most one <solver>", "line 5"}},
    {"StrayText", sceneWith("  0.5 kg\n"), "", 5, {"unexpected text", "0.5 kg", "<metriplex>"}},
    {"WrongRoot",
     "<?xml version=\"1.0\"?>\n<scene name=\"cli\">\n  <simulation dt=\"0.1\" t_end=\"1\"/>\n</scene>\n",
     "",
     2,
     {"root element", "<metriplex>", "<scene>"}},
    {"UnknownElement",
     sceneWith("  <spring_damper name=\"sd\" a=\"pivot\" b=\"pivot\"/>"),
     "",
     5,
     {"<spring_damper", "unknown element"}},
    {"MisspeltAttribute",
     sceneWith("  <mass name=\"bob\" mass=\"1\" positon=\"1 0 0\"/>"),
     "",
     5,
     {"<mass name=\"bob\">", "unknown attribute 'positon'"}},
    {"MisspeltRootAttribute",
     replaced(kSwingScene, "name=\"cli\"", "nmae=\"cli\""),
     "",
     2,
     {"<metriplex", "unknown attribute 'nmae'"}},
    {"MissingRequiredAttribute",
     sceneWith("  <mass name=\"bob\" position=\"1 0 0\"/>"),
     "",
     5,
     {"<mass name=\"bob\">", "missing required attribute 'mass'"}},
    {"NegativeMass",
     sceneWith("  <mass name=\"bob\" mass=\"-2\" position=\"1 0 0\"/>"),
     "",
     5,
     {"<mass name=\"bob\">", "'mass' must be positive"}},
    {"ZeroRestLength",
     sceneWith("  <mass name=\"bob\" mass=\"1\" position=\"1 0 0\"/>\n"
               "  <spring name=\"s\" a=\"pivot\" b=\"bob\" stiffness=\"10\" rest_length=\"0\"/>"),
     "",
     6,
     {"<spring name=\"s\">", "'rest_length' must be positive"}},
    {"NegativeHeatCapacity",
     sceneWith("  <reservoir name=\"env\" heat_capacity=\"-1\" temperature=\"1\"/>"),
     "",
     5,
     {"<reservoir name=\"env\">", "'heat_capacity' must be positive"}},
    {"ZeroTemperature",
     sceneWith("  <fixed_temperature name=\"wall\" temperature=\"0\"/>"),
     "",
     5,
     {"<fixed_temperature name=\"wall\">", "'temperature' must be positive"}},
    {"NanValue",
     sceneWith("  <mass name=\"bob\" mass=\"nan\" position=\"1 0 0\"/>"),
     "",
     5,
     {"<mass name=\"bob\">", "'mass' must be finite"}},
    {"InfValue",
     sceneWith("  <mass name=\"bob\" mass=\"1\" position=\"1 inf 0\"/>"),
     "",
     5,
     {"<mass name=\"bob\">", "'position' must be finite"}},
    {"NonNumericValue",
     sceneWith("  <mass name=\"bob\" mass=\"1\" position=\"1 0 0\"/>\n"
               "  <spring name=\"s\" a=\"pivot\" b=\"bob\" stiffness=\"stiff\" rest_length=\"1\"/>"),
     "",
     6,
     {"<spring name=\"s\">", "'stiffness'", "'stiff' is not a number"}},
    {"VectorWithTwoNumbers",
     sceneWith("  <mass name=\"bob\" mass=\"1\" velocity=\"0 1\"/>"),
     "",
     5,
     {"<mass name=\"bob\">", "'velocity' needs 3 numbers, got 2"}},
    {"DuplicateName",
     sceneWith("  <mass name=\"pivot\" mass=\"1\" position=\"1 0 0\"/>"),
     "",
     5,
     {"<mass name=\"pivot\">", "'pivot' is already used on line 4"}},
    {"UndeclaredMass",
     sceneWith("  <spring name=\"s\" a=\"pivot\" b=\"bob\" stiffness=\"10\" rest_length=\"1\"/>\n"
               "  <mass name=\"bob\" mass=\"1\" position=\"1 0 0\"/>"),
     "",
     5,
     {"<spring name=\"s\">", "'b'", "no mass or anchor named 'bob'"}},
    {"HeatLinkToNonThermalNode",
     sceneWith("  <reservoir name=\"env\" heat_capacity=\"1\" temperature=\"1\"/>\n"
               "  <heat_link name=\"h\" a=\"env\" b=\"pivot\" conductivity=\"1\"/>"),
     "",
     6,
     {"<heat_link name=\"h\">", "'b'", "no thermal node named 'pivot'"}},
    {"EntropyFormWithCurvedStiffness",
     kSwingScene,
     "--integrator eem-entropy",
     6,
     {"<thermo_spring name=\"spring\">", "stiffness_curvature"}},
    {"SceneEntropyIntegratorWithCurvedStiffness",
     replaced(kSwingScene, "t_end=\"1\"", "t_end=\"1\" integrator=\"eem-entropy\""),
     "",
     6,
     {"<thermo_spring name=\"spring\">", "stiffness_curvature"}},
    {"MissingSimulation",
     "<?xml version=\"1.0\"?>\n<metriplex name=\"cli\">\n  <anchor name=\"pivot\"/>\n</metriplex>\n",
     "",
     2,
     {"missing <simulation"}},
    {"DuplicateSimulation",
     sceneWith("  <simulation dt=\"0.5\" t_end=\"1\"/>\n" + kSwingElements),
     "",
     5,
     {"<simulation"}},
    {"UnknownSceneIntegrator",
     replaced(kSwingScene, "t_end=\"1\"", "t_end=\"1\" integrator=\"rk4\""),
     "",
     3,
     {"<simulation>", "integrator", "'rk4'"}},
    {"NothingToSimulate", sceneWith(""), "", 2, {"<metriplex"}},
    {"ReservoirEntropyOverflowingTemperature",
     sceneWith("  <reservoir name=\"env\" heat_capacity=\"1\" entropy=\"1000\"/>"),
     "",
     5,
     {"<reservoir name=\"env\">", "entropy"}},
    {"SolidWithNonPhysicalPoisson",
     sceneWith("  <solid name=\"b\" mesh=\"box\" cells=\"1 1 1\" young=\"10\" poisson=\"0.5\" density=\"1\"/>"),
     "",
     5,
     {"<solid name=\"b\">", "Poisson"}},
    {"SolidMeshFileMissing",
     sceneWith("  <solid name=\"b\" mesh=\"missing.msh\" young=\"10\" poisson=\"0.3\" density=\"1\"/>"),
     "",
     5,
     {"<solid name=\"b\">", "missing.msh", "cannot open"}},
    {"ClampOnUnknownSurface",
     sceneWith("  <solid name=\"b\" mesh=\"box\" cells=\"1 1 1\" young=\"10\" poisson=\"0.3\" density=\"1\"/>\n"
               "  <clamp solid=\"b\" surface=\"top\"/>"),
     "",
     6,
     {"<clamp>", "no surface or node set 'top'", "x0"}},
    // integers beyond their range, absurd meshes and names that would leave the output
    // directory: refused at the element's line
    {"CutbacksBeyondTheirRange",
     sceneWith("  <solver max_cutbacks=\"1e10\"/>\n  <mass name=\"m\" mass=\"1\"/>"),
     "",
     5,
     {"<solver>", "'max_cutbacks'", "from 0 to 50", "1e10"}},
    {"MeshTooLarge",
     sceneWith("  <solid name=\"b\" mesh=\"lblock\" level=\"100\" young=\"10\" poisson=\"0.3\" density=\"1\"/>"),
     "",
     5,
     {"<solid name=\"b\">", "3.6e+07 cells"}},
    {"SceneNameLeavesTheOutputDirectory",
     "<?xml version=\"1.0\"?>\n<metriplex name=\"../../escape\">\n  <simulation dt=\"0.1\" t_end=\"1\"/>\n"
     "  <mass name=\"m\" mass=\"1\"/>\n</metriplex>\n",
     "",
     2,
     {"scene name '../../escape'", "output files"}},
    {"SolidNameIsAnAbsolutePath",
     sceneWith("  <solid name=\"/tmp/x\" mesh=\"box\" cells=\"1 1 1\" young=\"10\" poisson=\"0.3\" density=\"1\"/>"),
     "",
     5,
     {"solid name '/tmp/x'", "output files"}},
    // degenerate joint geometry is an input error, not a singular tangent at the first step
    {"JointWithOneBodyAtBothEnds",
     sceneWith("  <body name=\"l\" mass=\"1\" inertia=\"1 1 1\" position=\"1 0 0\"/>\n"
               "  <joint name=\"j\" type=\"revolute\" a=\"l\" b=\"l\"/>"),
     "",
     6,
     {"<joint name=\"j\">", "two different ends"}},
    {"UniversalJointWithParallelAxes",
     sceneWith("  <body name=\"l\" mass=\"1\" inertia=\"1 1 1\" position=\"1 0 0\"/>\n"
               "  <joint name=\"j\" type=\"universal\" a=\"pivot\" b=\"l\" axis=\"0 0 1\" axis_b=\"0 0 2\"/>"),
     "",
     6,
     {"<joint name=\"j\">", "perpendicular", "cosine between them is 1"}},
    {"TractionWithoutLoad",
     sceneWith("  <solid name=\"b\" mesh=\"box\" cells=\"1 1 1\" young=\"10\" poisson=\"0.3\" density=\"1\"/>\n"
               "  <traction name=\"t\" solid=\"b\" surface=\"x1\"/>"),
     "",
     6,
     {"<traction name=\"t\">", "'traction'", "'total_force'"}},
};

class BadSceneTest : public CliTest, public ::testing::WithParamInterface<BadScene> {};

// exit 2, "file:line:" plus the element and what is wrong, and no output directory
TEST_P(BadSceneTest, ExitsTwoWithFileLineAndCauseAndWritesNothing) {
  const BadScene& c = GetParam();
  const fs::path scene = writeScene(c.xml);
  const Invocation r = metriplex("run " + quoted(scene) + " " + c.options + " --out " + quoted(outDir()));
  EXPECT_EQ(r.exitCode, kExitInvalidInput) << r.err;
  EXPECT_NE(r.err.find(scene.string() + ":" + std::to_string(c.line) + ":"), std::string::npos) << r.err;
  for (const std::string& mention : c.mentions) EXPECT_NE(r.err.find(mention), std::string::npos) << r.err;
  EXPECT_FALSE(fs::exists(outDir()));
}

INSTANTIATE_TEST_SUITE_P(Cli, BadSceneTest, ::testing::ValuesIn(kBadScenes),
                         [](const ::testing::TestParamInfo<BadScene>& info) { return info.param.label; });

// A missing file has no line: the message names the path.
TEST_F(CliTest, MissingSceneFileExitsTwoAndWritesNothing) {
  const fs::path scene = dir_ / "no_such_scene.xml";
  const Invocation r = metriplex("run " + quoted(scene) + " --out " + quoted(outDir()));
  EXPECT_EQ(r.exitCode, kExitInvalidInput);
  EXPECT_NE(r.err.find(scene.string() + ": cannot open"), std::string::npos) << r.err;
  EXPECT_FALSE(fs::exists(outDir()));
}

// One invalid command line on the valid swing scene and the words its message must contain.
struct BadOptions {
  std::string label;
  std::string command;  // "run SCENE --out DIR" or "compare SCENE --out DIR", then options
  std::string options;
  std::vector<std::string> mentions;
};

std::ostream& operator<<(std::ostream& os, const BadOptions& c) { return os << c.label; }

const std::vector<BadOptions> kBadOptions = {
    {"UnknownIntegrator", "run", "--integrator rk4", {"unknown integrator 'rk4'"}},
    {"NegativeStep", "run", "--dt -0.1", {"--dt", "positive"}},
    {"ZeroEndTime", "run", "--t-end 0", {"--t-end", "positive"}},
    {"UnknownOption", "run", "--frobnicate", {"--frobnicate"}},
    {"CompareUnknownIntegrator", "compare", "--integrators eem,rk4", {"unknown integrator 'rk4'"}},
    // the second integrator cannot take this scene: nothing may be run before that is known
    {"CompareIntegratorTheSceneRejects", "compare", "--integrators eem,eem-entropy", {"stiffness_curvature"}},
    {"NegativeRelativeTolerance", "run", "--integrator ida --rtol -1e-6", {"--rtol", "positive"}},
    {"MaxOrderSix", "run", "--integrator ida --max-order 6", {"--max-order", "1 to 5"}},
    {"MaxOrderTwice", "run", "--integrator ida-bdf2 --max-order 3", {"--max-order 3", "'ida-bdf2'", "to 2 already"}},
    {"MaxOrderFiveTwice", "run", "--integrator ida-bdf2 --max-order 5", {"--max-order 5", "to 2 already"}},
    {"BdfOrderSix", "run", "--integrator ida-bdf6", {"unknown integrator 'ida-bdf6'"}},
    {"BenchUnknownIntegrator", "bench", "--integrators eem,rk4", {"unknown integrator 'rk4'"}},
    {"BenchNegativeTolerance", "bench", "--rtols 1e-3,-1e-6", {"--rtols", "-1e-06"}},
    {"BenchZeroStep", "bench", "--dts 0.1,0", {"--dts", "positive"}},
    {"BenchZeroRepeats", "bench", "--repeats 0", {"--repeats"}},
    {"TooManySteps", "run", "--dt 1e-12", {"--dt", "steps; at most 1e9"}},
    {"CompareWithoutIntegrators", "compare", "--integrators ''", {"--integrators", "no integrator"}},
    {"BenchWithoutIntegrators", "bench", "--integrators ''", {"--integrators", "no integrator"}},
};

// A face pushed through the opposite one would turn the cell inside out, where C = F^T F and
// the energy still look regular: the run stops there as a solver failure naming the cell (it
// used to finish with exit 0 in the mirrored configuration)
TEST_F(CliTest, InvertingACellIsASolverFailure) {
  const Invocation r = metriplex(
      "run " +
      quoted(writeScene(sceneWith(
          "  <solid name=\"bar\" mesh=\"box\" cells=\"1 1 1\" material=\"svk\" young=\"1e3\" poisson=\"0.3\" "
          "density=\"10\"/>\n  <clamp solid=\"bar\" surface=\"x0\"/>\n  <prescribed_displacement solid=\"bar\" "
          "surface=\"x1\" displacement=\"-2 0 0\" profile=\"ramp\" end=\"1\"/>"))) +
      " --out " + quoted(outDir()));
  EXPECT_EQ(r.exitCode, kExitSolverFailure) << r.err;
  EXPECT_NE(r.err.find("solver failure at step 5 (t = 0.5)"), std::string::npos) << r.err;
  // the failure names the cell whose residual went non-finite and the dof
  EXPECT_NE(r.err.find("the residual of bar.cell0 at dof 0 (position) was not finite"), std::string::npos) << r.err;
  EXPECT_TRUE(fs::exists(outDir() / "history.csv"));
}

// SIGINT (run) and SIGTERM (compare) stop at a step boundary with exit code 4: the history is
// complete up to that step (no .part file) and says where and why it ends; a comparison starts
// no further integrator.
TEST_F(CliTest, ASignalStopsAtAStepBoundaryWithAMarkedHistory) {
  const std::string longRun = quoted(fs::path(mpx::test::scenePath("two_thermo_springs.xml"))) + " --t-end 1e7";
  // the signal goes once the run has begun writing its history, however slow the machine
  const auto signalOnceRunning = [](const char* signal, const fs::path& history) {
    return "sh -c 'while [ ! -s " + history.string() + " ]; do sleep 0.05; done; kill -" + signal + " $PPID' & exec ";
  };
  const Invocation run = metriplex("run " + longRun + " --out " + quoted(outDir()),
                                   signalOnceRunning("INT", outDir() / "history.csv.part"));
  EXPECT_EQ(run.exitCode, 4) << run.err;
  EXPECT_NE(run.err.find("interrupted after step"), std::string::npos) << run.err;
  ASSERT_TRUE(fs::exists(outDir() / "history.csv"));
  EXPECT_FALSE(fs::exists(outDir() / "history.csv.part"));
  std::istringstream history(readFile(outDir() / "history.csv"));
  std::vector<std::string> lines;
  for (std::string line; std::getline(history, line);) lines.push_back(line);
  ASSERT_GE(lines.size(), 3u);
  const std::size_t rows = lines.size() - 2;  // the header and the marker
  EXPECT_EQ(lines.back().rfind("# interrupted after step " + std::to_string(rows - 1) + " (t = ", 0), 0u)
      << lines.back();
  const auto columns = [](const std::string& line) { return std::count(line.begin(), line.end(), ','); };
  EXPECT_EQ(columns(lines[lines.size() - 2]), columns(lines[0])) << "the last row is complete";

  const Invocation compare = metriplex("compare " + longRun + " --integrators eem,midpoint --out " + quoted(outDir()),
                                       signalOnceRunning("TERM", outDir() / "eem" / "history.csv.part"));
  EXPECT_EQ(compare.exitCode, 4) << compare.err;
  EXPECT_NE(compare.out.find("interrupted after step"), std::string::npos) << compare.out;
  EXPECT_TRUE(fs::exists(outDir() / "eem" / "history.csv"));
  EXPECT_FALSE(fs::exists(outDir() / "midpoint")) << "an integrator was started after the interruption";
}

// A misspelt subcommand is named; an output directory that cannot be made names --out
TEST_F(CliTest, UnknownSubcommandAndUnusableOutputDirectoryAreNamed) {
  const Invocation unknown = metriplex("rnu " + quoted(writeScene(kSwingScene)));
  EXPECT_EQ(unknown.exitCode, kExitInvalidInput);
  EXPECT_NE(unknown.err.find("unknown subcommand 'rnu'"), std::string::npos) << unknown.err;
  const Invocation badOut = metriplex("run " + quoted(writeScene(kSwingScene)) + " --out /proc/no/such/dir");
  EXPECT_EQ(badOut.exitCode, kExitInvalidInput);
  EXPECT_NE(badOut.err.find("option --out: cannot create the directory /proc/no/such/dir"), std::string::npos)
      << badOut.err;
  // a directory where the history is to be renamed into place: refused before the run
  fs::create_directories(outDir() / "history.csv");
  const Invocation blocked = metriplex("run " + quoted(writeScene(kSwingScene)) + " --out " + quoted(outDir()));
  EXPECT_EQ(blocked.exitCode, kExitInvalidInput);
  EXPECT_NE(blocked.err.find("history.csv exists and is not a file"), std::string::npos) << blocked.err;
  EXPECT_FALSE(fs::exists(outDir() / "history.csv.part"));
}

// IDA's rate form cannot impose a displacement step by step: refused before anything is written,
// naming the scene, the element and its line (run, and bench when ida is all it is asked for).
TEST_F(CliTest, IdaRefusesAPrescribedDisplacement) {
  const std::string xml = readFile(mpx::test::scenePath("stretched_bar.xml"));
  const fs::path scene = writeScene(xml);
  const auto line = 1 + std::count(xml.begin(), xml.begin() + xml.find("<prescribed_displacement"), '\n');
  const std::string where = scene.string() + ":" + std::to_string(line) + ": <prescribed_displacement>";
  for (const std::string command : {"run --integrator ida", "bench --integrators ida"}) {
    const Invocation r = metriplex(command + " " + quoted(scene) + " --out " + quoted(outDir()));
    EXPECT_EQ(r.exitCode, kExitInvalidInput) << command << ": " << r.err;
    EXPECT_NE(r.err.find(where), std::string::npos) << where << " in " << r.err;
    EXPECT_FALSE(fs::exists(outDir()));
  }
}

// A scene IDA cannot run is benched against EEM at a 64th of the scene's step, shown converged
// against EEM at a 32nd; ida leaves the sweep with the reason, and the errors fall at order 2.
TEST_F(CliTest, BenchMeasuresASceneIdaRefusesAgainstFineEem) {
  std::string xml = readFile(mpx::test::scenePath("stretched_bar.xml"));
  for (const auto& [from, to] : {std::pair<std::string, std::string>{"cells=\"8 2 2\"", "cells=\"2 1 1\""},
                                 {"dt=\"0.02\" t_end=\"4\"", "dt=\"0.05\" t_end=\"0.5\""}}) {
    ASSERT_NE(xml.find(from), std::string::npos) << from;
    xml.replace(xml.find(from), from.size(), to);
  }
  const Invocation r = metriplex("bench " + quoted(writeScene(xml)) +
                                 " --integrators eem,ida --dts 0.0125,0.00625 --repeats 1 --out " + quoted(outDir()));
  ASSERT_EQ(r.exitCode, kExitSuccess) << r.err;
  EXPECT_NE(r.out.find("ida left out"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("reference: eem dt 0.00078125"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("differs from EEM at dt 0.0015625"), std::string::npos) << r.out;
  const std::vector<std::string> lines = splitLines(readFile(outDir() / "work_precision.csv"));
  ASSERT_EQ(lines.size(), 1u + 2);  // eem over 2 steps, both in the asymptotic range
  const std::vector<std::string> header = splitFields(lines.front());
  const auto errorColumn = std::find(header.begin(), header.end(), "error") - header.begin();
  const double coarse = std::stod(splitFields(lines[1])[errorColumn]),
               fine = std::stod(splitFields(lines[2])[errorColumn]);
  EXPECT_NEAR(coarse / fine, 4.0, 1.0) << coarse << " " << fine;
}

class BadOptionsTest : public CliTest, public ::testing::WithParamInterface<BadOptions> {};

TEST_P(BadOptionsTest, ExitsTwoWithCauseAndWritesNothing) {
  const BadOptions& c = GetParam();
  const fs::path scene = writeScene(kSwingScene);
  const Invocation r = metriplex(c.command + " " + quoted(scene) + " --out " + quoted(outDir()) + " " + c.options);
  EXPECT_EQ(r.exitCode, kExitInvalidInput) << r.err;
  for (const std::string& mention : c.mentions) EXPECT_NE(r.err.find(mention), std::string::npos) << r.err;
  EXPECT_FALSE(fs::exists(outDir()));
}

INSTANTIATE_TEST_SUITE_P(Cli, BadOptionsTest, ::testing::ValuesIn(kBadOptions),
                         [](const ::testing::TestParamInfo<BadOptions>& info) { return info.param.label; });

// The header names the conserved and exchanged quantities; every row is complete.
void expectCompleteHistory(const std::vector<std::string>& lines, std::size_t rows) {
  ASSERT_EQ(lines.size(), rows + 1);
  const std::vector<std::string> header = splitFields(lines.front());
  for (const char* column : {"time", "energy", "entropy", "dissipated_energy", "external_work", "boundary_heat",
                             "boundary_entropy", "entropy_production", "momentum_x", "momentum_y", "momentum_z",
                             "angular_momentum_x", "angular_momentum_y", "angular_momentum_z", "newton_iterations",
                             "cutbacks", "constraint_violation", "temperature_spring", "temperature_wall"})
    EXPECT_NE(std::find(header.begin(), header.end(), column), header.end()) << column;
  for (std::size_t i = 1; i < lines.size(); ++i) EXPECT_EQ(splitFields(lines[i]).size(), header.size()) << lines[i];
}

// one row per step plus the initial state, from t = 0 to t_end, and no .part file left
TEST_F(CliTest, RunWritesOneHistoryRowPerStepPlusOne) {
  const Invocation r = metriplex("run " + quoted(writeScene(kSwingScene)) + " --out " + quoted(outDir()));
  ASSERT_EQ(r.exitCode, kExitSuccess) << r.err;
  const std::vector<std::string> lines = splitLines(readFile(outDir() / "history.csv"));
  ASSERT_NO_FATAL_FAILURE(expectCompleteHistory(lines, kSwingSteps + 1));
  EXPECT_EQ(std::stod(splitFields(lines[1]).front()), 0.0);
  EXPECT_EQ(std::stod(splitFields(lines.back()).front()), 1.0);
  EXPECT_FALSE(fs::exists(outDir() / "history.csv.part"));
}

// DIR/summary.json says what the printed summary says, machine-readably
TEST_F(CliTest, RunWritesItsSummaryAsJson) {
  const Invocation r = metriplex("run " + quoted(writeScene(kSwingScene)) + " --out " + quoted(outDir()));
  ASSERT_EQ(r.exitCode, kExitSuccess) << r.err;
  const std::string json = readFile(outDir() / "summary.json");
  EXPECT_EQ(json.front(), '{');
  for (const std::string& field :
       std::vector<std::string>{"\"status\": \"ok\"", "\"integrator\": \"eem\"",
                                "\"steps\": " + std::to_string(kSwingSteps), "\"max_relative_energy_drift\": "})
    EXPECT_NE(json.find(field), std::string::npos) << field << " in " << json;
  EXPECT_FALSE(fs::exists(outDir() / "summary.json.part"));
}

// metriplex plot renders a run's history to PNGs in its directory; a directory without a
// history is invalid input
TEST_F(CliTest, PlotRendersTheHistoryToPng) {
  ASSERT_EQ(metriplex("run " + quoted(writeScene(kSwingScene)) + " --out " + quoted(outDir())).exitCode, kExitSuccess);
  const Invocation r = metriplex("plot " + quoted(outDir()));
  ASSERT_EQ(r.exitCode, kExitSuccess) << r.err;
  for (const char* png : {"energy.png", "entropy.png", "constraint_violation.png"}) {
    const std::string picture = readFile(outDir() / png);
    EXPECT_EQ(picture.substr(1, 3), "PNG") << png;
    EXPECT_NE(r.out.find(png), std::string::npos) << r.out;
  }
  const Invocation missing = metriplex("plot " + quoted(dir_ / "nothing"));
  EXPECT_EQ(missing.exitCode, kExitInvalidInput);
  EXPECT_NE(missing.err.find("history.csv"), std::string::npos) << missing.err;
  EXPECT_FALSE(fs::exists(dir_ / "nothing"));
}

// A solid writes a ParaView series, one frame per --output-interval, each frame with all of its
// nodes and cells, and a picture of the last frame; no .part file stays behind.
TEST_F(CliTest, SolidRunWritesAParaViewSeriesAndAPicture) {
  const std::string scene = sceneWith(
      "  <solid name=\"block\" mesh=\"box\" size=\"2 1 1\" cells=\"2 1 1\" young=\"1000\" poisson=\"0.3\" "
      "density=\"10\" angular_velocity=\"0 0 1\"/>");
  const Invocation r =
      metriplex("run " + quoted(writeScene(scene)) + " --output-interval 0.5 --out " + quoted(outDir()));
  ASSERT_EQ(r.exitCode, kExitSuccess) << r.err;
  const std::string pvd = readFile(outDir() / "block.pvd");
  for (int frame = 0; frame < 3; ++frame) {  // t = 0, 0.5, 1
    const std::string file = "block/frame_0000" + std::to_string(frame) + ".vtu";
    EXPECT_NE(pvd.find(file), std::string::npos) << pvd;
    const std::string vtu = readFile(outDir() / file);
    EXPECT_NE(vtu.find("NumberOfPoints=\"12\" NumberOfCells=\"2\""), std::string::npos) << file;
    for (const char* field : {"displacement", "velocity", "cauchy_stress", "von_mises", "viscous_strain"})
      EXPECT_NE(vtu.find(field), std::string::npos) << file << " lacks " << field;
  }
  EXPECT_FALSE(fs::exists(outDir() / "block" / "frame_00003.vtu"));
  EXPECT_TRUE(fs::exists(outDir() / "block.png")) << r.err;
  for (const auto& entry : fs::recursive_directory_iterator(outDir()))
    EXPECT_NE(entry.path().extension(), ".part") << entry.path();
}

// A thermal solid adds its temperature range to history.csv and temperature and heat flux to
// its frames; the held face's heat and entropy are accumulated
TEST_F(CliTest, ThermalSolidRunWritesTemperaturesAndBoundaryColumns) {
  const std::string scene = sceneWith(
      "  <solid name=\"block\" mesh=\"box\" size=\"2 1 1\" cells=\"2 1 1\" young=\"1000\" poisson=\"0.3\" "
      "density=\"10\" heat_capacity=\"10\" conductivity=\"5\" temperature=\"300\"/>\n"
      "  <prescribed_temperature solid=\"block\" surface=\"x0\" temperature=\"350\"/>");
  const Invocation r =
      metriplex("run " + quoted(writeScene(scene)) + " --output-interval 0.5 --out " + quoted(outDir()));
  ASSERT_EQ(r.exitCode, kExitSuccess) << r.err;
  const std::vector<std::string> lines = splitLines(readFile(outDir() / "history.csv"));
  const std::vector<std::string> header = splitFields(lines.front());
  const auto column = [&](const std::string& name) {
    const auto it = std::find(header.begin(), header.end(), name);
    if (it == header.end()) ADD_FAILURE() << "history.csv lacks " << name;
    return it == header.end() ? NAN : std::stod(splitFields(lines.back())[it - header.begin()]);
  };
  EXPECT_NEAR(column("temperature_max_block"), 350.0, 1e-9);
  EXPECT_GT(column("temperature_min_block"), 300.0);
  EXPECT_GT(column("boundary_heat"), 0.0);
  EXPECT_GT(column("boundary_entropy"), 0.0);
  EXPECT_GT(column("entropy_production"), 0.0);
  const std::string vtu = readFile(outDir() / "block" / "frame_00002.vtu");
  for (const char* field : {"\"temperature\"", "\"heat_flux\""})
    EXPECT_NE(vtu.find(field), std::string::npos) << "frame lacks " << field;
}

// In the entropy form the history still reports temperatures, and they are the temperature
// form's (the two EEM forms solve the same discrete system, docs/theory.md section 9.7)
TEST_F(CliTest, ThermalSolidReportsTheSameTemperaturesInTheEntropyForm) {
  const fs::path scene = writeScene(
      sceneWith("  <solid name=\"block\" mesh=\"box\" size=\"2 1 1\" cells=\"2 1 1\" young=\"1000\" poisson=\"0.3\" "
                "density=\"10\" heat_capacity=\"10\" conductivity=\"5\" expansion=\"1e-3\" temperature=\"300\"/>\n"
                "  <convection name=\"c\" solid=\"block\" surface=\"x0\" coefficient=\"20\" ambient=\"350\"/>"));
  std::vector<double> means;
  for (const char* form : {"eem-temperature", "eem-entropy"}) {
    const fs::path out = outDir() / form;
    const Invocation r = metriplex("run " + quoted(scene) + " --integrator " + form + " --out " + quoted(out));
    ASSERT_EQ(r.exitCode, kExitSuccess) << r.err;
    const std::vector<std::string> lines = splitLines(readFile(out / "history.csv"));
    const std::vector<std::string> header = splitFields(lines.front());
    const auto it = std::find(header.begin(), header.end(), "temperature_mean_block");
    ASSERT_NE(it, header.end());
    means.push_back(std::stod(splitFields(lines.back())[it - header.begin()]));
  }
  EXPECT_GT(means[0], 300.5);
  EXPECT_NEAR(means[1], means[0], 1e-9 * means[0]);
}

// --dt and --t-end replace the scene's step and end time
TEST_F(CliTest, StepAndEndTimeOptionsOverrideTheScene) {
  const Invocation r = metriplex("run " + quoted(writeScene(kSwingScene)) +
                                 " --integrator midpoint --dt 0.25 "
                                 "--t-end 0.5 --out " +
                                 quoted(outDir()));
  ASSERT_EQ(r.exitCode, kExitSuccess) << r.err;
  const std::vector<std::string> lines = splitLines(readFile(outDir() / "history.csv"));
  ASSERT_NO_FATAL_FAILURE(expectCompleteHistory(lines, 3));
  EXPECT_EQ(std::stod(splitFields(lines.back()).front()), 0.5);
}

// Newton is allowed one iteration and no cut-back, so the first step that moves (the force
// ramps up from t = 0.5) cannot converge; the resting steps before it can.
TEST_F(CliTest, SolverFailureExitsThreeAndKeepsTheGoodSteps) {
  const std::string scene = sceneWith(
      "  <solver max_iterations=\"1\" max_cutbacks=\"0\"/>\n"
      "  <mass name=\"bob\" mass=\"1\" position=\"1 0 0\"/>\n"
      "  <spring name=\"s\" a=\"pivot\" b=\"bob\" stiffness=\"1e6\" rest_length=\"1\"/>\n"
      "  <force name=\"kick\" on=\"bob\" force=\"0 1000 0\" profile=\"ramp\" start=\"0.5\" end=\"0.625\"/>");
  const Invocation r =
      metriplex("run " + quoted(writeScene(scene)) + " --integrator midpoint --out " + quoted(outDir()));
  EXPECT_EQ(r.exitCode, kExitSolverFailure) << r.err;
  EXPECT_NE(r.err.find("step 5 (t = 0.5)"), std::string::npos) << r.err;
  const std::vector<std::string> lines = splitLines(readFile(outDir() / "history.csv"));
  ASSERT_EQ(lines.size(), 1 + 5 + 1);  // header, t = 0, 0.125, ..., 0.5, failure line
  EXPECT_EQ(std::stod(splitFields(lines[5]).front()), 0.5);
  EXPECT_EQ(lines.back().rfind("# solver failure", 0), 0u) << lines.back();
  const std::string json = readFile(outDir() / "summary.json");
  EXPECT_NE(json.find("\"status\": \"failed\""), std::string::npos) << json;
  EXPECT_NE(json.find("\"failure\": {\"step\": 5, \"time\": 0.5"), std::string::npos) << json;
}

// Both default integrators run, each into its own directory, and the table reports them ok.
TEST_F(CliTest, CompareRunsEemAndMidpoint) {
  const Invocation r = metriplex("compare " + quoted(writeScene(kSwingScene)) + " --out " + quoted(outDir()));
  ASSERT_EQ(r.exitCode, kExitSuccess) << r.err;
  for (const std::string integrator : {"eem", "midpoint"}) {
    expectCompleteHistory(splitLines(readFile(outDir() / integrator / "history.csv")), kSwingSteps + 1);
    bool reportedOk = false;
    for (const std::string& line : splitLines(r.out))
      reportedOk |= line.rfind(integrator + " ", 0) == 0 && line.size() >= 2 && line.substr(line.size() - 2) == "ok";
    EXPECT_TRUE(reportedOk) << r.out;
  }
}

// IDA writes one row per output time and reports its statistics.
TEST_F(CliTest, IdaRunWritesOneRowPerOutputTime) {
  const Invocation r = metriplex("run " + quoted(writeScene(kSwingScene)) +
                                 " --integrator ida --rtol 1e-8 --atol 1e-10 --dt-out 0.25 --out " + quoted(outDir()));
  ASSERT_EQ(r.exitCode, kExitSuccess) << r.err;
  ASSERT_NO_FATAL_FAILURE(expectCompleteHistory(splitLines(readFile(outDir() / "history.csv")), 4 + 1));
  EXPECT_NE(r.out.find("error-test failures"), std::string::npos) << r.out;
}

// A small sweep: one CSV row per run with finite numbers, the three plots, a cached reference.
TEST_F(CliTest, BenchWritesTheWorkPrecisionTableAndPlots) {
  const std::string command = "bench " + quoted(writeScene(kSwingScene)) +
                              " --dts 0.25,0.125 --rtols 1e-4,1e-6 --repeats 1 --out " + quoted(outDir());
  const Invocation r = metriplex(command);
  ASSERT_EQ(r.exitCode, kExitSuccess) << r.err;
  const std::vector<std::string> lines = splitLines(readFile(outDir() / "work_precision.csv"));
  ASSERT_EQ(lines.size(), 1u + 3 * 2 + 2);  // eem, midpoint, trapezoidal over 2 steps; ida over 2 tolerances
  const std::vector<std::string> header = splitFields(lines.front());
  for (const char* column : {"integrator", "dt", "rtol", "cpu_seconds", "steps", "newton_iterations", "ida_steps",
                             "error", "energy_drift", "entropy_violations", "status"})
    ASSERT_NE(std::find(header.begin(), header.end(), column), header.end()) << column;
  auto field = [&](const std::vector<std::string>& row, const char* column) {
    return row[std::find(header.begin(), header.end(), column) - header.begin()];
  };
  for (std::size_t i = 1; i < lines.size(); ++i) {
    const std::vector<std::string> row = splitFields(lines[i]);
    ASSERT_EQ(row.size(), header.size()) << lines[i];
    for (const char* column : {"cpu_seconds", "error", "energy_drift"})
      EXPECT_TRUE(std::isfinite(std::stod(field(row, column)))) << lines[i];
    EXPECT_EQ(field(row, "status"), "ok") << lines[i];
  }
  for (const char* plot : {"work_precision.png", "energy_error.png", "entropy.png"})
    EXPECT_GT(fs::file_size(outDir() / plot), 1000u) << plot;
  // the second sweep reuses the reference instead of recomputing it
  const Invocation again = metriplex(command);
  ASSERT_EQ(again.exitCode, kExitSuccess) << again.err;
  EXPECT_NE(again.out.find("reference: cached"), std::string::npos) << again.out;
  // a damaged cache (a position that is not a finite number) is computed again, not believed
  const std::string cache = readFile(outDir() / "reference.csv");
  const std::size_t row = cache.find('\n') + 1;
  std::ofstream(outDir() / "reference.csv") << cache.substr(0, row) + "nan" + cache.substr(cache.find(',', row));
  const Invocation damaged = metriplex(command);
  ASSERT_EQ(damaged.exitCode, kExitSuccess) << damaged.err;
  EXPECT_EQ(damaged.out.find("reference: cached"), std::string::npos) << damaged.out;
  EXPECT_EQ(readFile(outDir() / "reference.csv"), cache);
}

// Each help text exits 0 and lists what it documents.
TEST_F(CliTest, HelpExitsZeroAndListsTheOptions) {
  const std::vector<std::pair<std::string, std::vector<std::string>>> helps = {
      {"--help", {"run", "compare", "bench", "Exit codes"}},
      {"bench --help", {"SCENE", "--integrators", "--dts", "--rtols", "--repeats", "--out"}},
      {"run --help", {"SCENE", "--integrator", "--dt", "--t-end", "--out"}},
      {"compare --help", {"SCENE", "--integrators", "--dt", "--t-end", "--out"}},
  };
  for (const auto& [arguments, mentions] : helps) {
    const Invocation r = metriplex(arguments);
    EXPECT_EQ(r.exitCode, kExitSuccess) << arguments;
    for (const std::string& mention : mentions) EXPECT_NE(r.out.find(mention), std::string::npos) << arguments;
  }
}

}  // namespace
