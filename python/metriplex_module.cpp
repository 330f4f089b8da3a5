// The Python module metriplex._metriplex (pybind11): run a scene file or a scene built in code
// with every option of `metriplex run`, and get its history, summary and frames as numpy
// arrays and dicts. The run itself is tools/session's, as for the command line; the history
// columns are history.csv's (HistoryColumns), the frames bodies.csv's and joints.csv's.
#include "tools/output/element_budget.hpp"
#include "tools/output/frame_sampler.hpp"
#include "tools/output/history_columns.hpp"
#include "tools/output/output_schedule.hpp"
#include "tools/session/run_session.hpp"

#include "engine/core/input_error.hpp"

#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include <map>

namespace py = pybind11;

namespace mpx {

namespace {

// Columns of numbers gathered in memory during a run, turned into numpy arrays after it.
struct Columns {
  std::vector<std::string> names;
  std::vector<std::vector<double>> values;
  explicit Columns(std::vector<std::string> columnNames) : names(std::move(columnNames)), values(names.size()) {}
  // A time and the values after it, one per remaining column.
  template <class Values>
  void append(double time, const Values& row) {
    values[0].push_back(time);
    std::size_t i = 1;
    for (double value : row) values[i++].push_back(value);
  }
  py::dict toDict() const {
    py::dict dict;
    for (std::size_t i = 0; i < names.size(); ++i)
      dict[py::str(names[i])] = py::array_t<double>(values[i].size(), values[i].data());
    return dict;
  }
};

// What a run hands back: the history, bodies' poses, joints' coordinates and the budget per
// element at the output times of --output-interval, and the summary as summary.json has it.
struct Recording {
  std::vector<std::string> historyNames;
  std::vector<std::vector<double>> history;
  std::map<std::string, Columns> bodies, joints, budget;
  std::string summary;
};

py::dict toDict(const std::map<std::string, Columns>& groups) {
  py::dict dict;
  for (const auto& [name, columns] : groups) dict[py::str(name)] = columns.toDict();
  return dict;
}

// Integrates with the GIL released; the recorders fill plain C++ containers.
Recording record(const RunRequest& request) {
  py::gil_scoped_release release;
  // a Python run writes files only where `out` says
  if (request.out.empty() && (request.checkpointEvery > 0 || !request.restart.empty()))
    throw InputError("options checkpoint_every and restart need an output directory (out=...)");
  const PreparedRun run = prepareRun(request);
  Recording recording;
  const HistoryColumns columns(run.scene);
  recording.historyNames = columns.names();
  recording.history.resize(columns.names().size());
  for (const BodyFrame& body : run.scene.bodies)
    recording.bodies.emplace(body.name, Columns({"time", "x", "y", "z", "qw", "qx", "qy", "qz"}));
  for (const JointCoordinate& joint : run.scene.joints)
    recording.joints.emplace(joint.name(), Columns({"time", "position", "velocity"}));
  std::optional<ElementBudget> budget;
  if (request.budget) {
    budget.emplace(run.scene);
    std::vector<std::string> names{"time"};
    names.insert(names.end(), ElementBudget::columnNames().begin(), ElementBudget::columnNames().end());
    for (const std::string& group : budget->groups()) recording.budget.emplace(group, Columns(names));
  }
  FrameSampler sampler(run.scene);
  OutputSchedule schedule(run.frameInterval);
  std::vector<double> values;

  RunOutputs outputs;
  outputs.files = !request.out.empty();
  outputs.checkpoints = outputs.files;
  outputs.checkpointEvery = request.checkpointEvery;
  outputs.observe = [&](const StepRecord& step) {
    columns.values(step, values);
    for (std::size_t i = 0; i < values.size(); ++i) recording.history[i].push_back(values[i]);
    if (!schedule.due(step.time)) return;
    sampler.sample(step.state->data());
    for (std::size_t b = 0; b < run.scene.bodies.size(); ++b) {
      const BodyPose& pose = sampler.bodies()[b];
      const Eigen::Quaterniond& q = pose.orientation;
      recording.bodies.at(run.scene.bodies[b].name)
          .append(step.time,
                  std::array{pose.position.x(), pose.position.y(), pose.position.z(), q.w(), q.x(), q.y(), q.z()});
    }
    for (std::size_t j = 0; j < run.scene.joints.size(); ++j)
      recording.joints.at(run.scene.joints[j].name())
          .append(step.time, std::array{sampler.joints()[j].position, sampler.joints()[j].velocity});
    if (!budget) return;
    const std::vector<ElementBudget::Row>& rows = budget->rows(step);
    for (std::size_t g = 0; g < rows.size(); ++g) recording.budget.at(budget->groups()[g]).append(step.time, rows[g]);
  };
  const RunResult result = executeRun(run, outputs);
  recording.summary = summaryJson(run, result.summary);
  return recording;
}

// One attribute of Scene.add from a Python value: bool, int, float, str or a sequence of numbers.
AttributeValue attributeOf(const std::string& name, const py::handle& value) {
  if (py::isinstance<py::bool_>(value)) return AttributeValue(value.cast<bool>());
  if (py::isinstance<py::int_>(value)) return AttributeValue(value.cast<int>());
  if (py::isinstance<py::float_>(value)) return AttributeValue(value.cast<double>());
  if (py::isinstance<py::str>(value)) return AttributeValue(value.cast<std::string>());
  try {
    return AttributeValue(value.cast<std::vector<double>>());
  } catch (const py::cast_error&) {
    throw InputError("attribute '" + name + "' must be a bool, a number, a string or a sequence of numbers, not " +
                     py::str(py::type::of(value)).cast<std::string>());
  }
}

py::object run(const py::object& scene, const std::string& integrator, std::optional<double> dt,
               std::optional<double> tEnd, const std::string& out, std::optional<double> outputInterval, bool adaptive,
               std::optional<double> rtol, std::optional<double> atol, std::optional<int> maxOrder, bool sundialsKlu,
               std::optional<double> dtOut, int checkpointEvery, const std::string& restart, bool budget,
               bool urdfLimits) {
  RunRequest request;
  if (py::isinstance<SceneSpec>(scene)) {
    request.spec = &scene.cast<const SceneSpec&>();
    request.scene = request.spec->label;
  } else {
    request.scene = py::str(scene).cast<std::string>();  // a str or a pathlib.Path
  }
  request.integrator = integrator;
  request.dt = dt;
  request.tEnd = tEnd;
  request.out = out;
  request.frameInterval = outputInterval;
  request.adaptive = adaptive;
  request.relativeTolerance = rtol;
  request.absoluteTolerance = atol;
  request.maxOrder = maxOrder;
  request.sundialsKlu = sundialsKlu;
  request.outputStep = dtOut;
  request.checkpointEvery = checkpointEvery;
  request.restart = restart;
  request.budget = budget;
  request.urdfLimits = urdfLimits;
  const Recording recording = record(request);

  py::dict history;
  for (std::size_t i = 0; i < recording.historyNames.size(); ++i)
    history[py::str(recording.historyNames[i])] =
        py::array_t<double>(recording.history[i].size(), recording.history[i].data());
  const py::object summary = py::module_::import("json").attr("loads")(recording.summary);
  return py::module_::import("metriplex")
      .attr("Result")(history, summary, toDict(recording.bodies), toDict(recording.joints), toDict(recording.budget));
}

ThermalVariable thermalVariableNamed(const std::string& name) {
  if (name != "temperature" && name != "entropy")
    throw InputError("thermal_variable must be 'temperature' or 'entropy', got '" + name + "'");
  return name == "entropy" ? ThermalVariable::Entropy : ThermalVariable::Temperature;
}

}  // namespace

}  // namespace mpx

PYBIND11_MODULE(_metriplex, module) {
  using namespace mpx;
  module.doc() = "Metriplex: flexible multibody dynamics with dissipation, EEM and standard integrators";
  // invalid input: the same file:line message as the command line's, as a ValueError
  py::register_exception<InputError>(module, "InputError", PyExc_ValueError);

  py::class_<SceneSpec>(module, "Scene", "A scene built in code: the elements and settings of a scene file")
      .def(py::init([](const std::string& name) {
             SceneSpec scene;
             scene.name = name;
             scene.label = "scene '" + name + "' built in Python";
             return scene;
           }),
           py::arg("name") = "scene")
      .def_readwrite("name", &SceneSpec::name)
      .def_property(
          "dt", [](const SceneSpec& s) { return s.settings.dt; }, [](SceneSpec& s, double v) { s.settings.dt = v; })
      .def_property(
          "t_end", [](const SceneSpec& s) { return s.settings.tEnd; },
          [](SceneSpec& s, double v) { s.settings.tEnd = v; })
      .def_property(
          "integrator", [](const SceneSpec& s) { return s.settings.integrator; },
          [](SceneSpec& s, const std::string& v) { s.settings.integrator = v; })
      .def_property(
          "thermal_variable",
          [](const SceneSpec& s) {
            return s.settings.thermalVariable == ThermalVariable::Entropy ? "entropy" : "temperature";
          },
          [](SceneSpec& s, const std::string& v) { s.settings.thermalVariable = thermalVariableNamed(v); })
      .def_property(
          "gravity",
          [](const SceneSpec& s) {
            return std::vector<double>{s.gravity.x(), s.gravity.y(), s.gravity.z()};
          },
          [](SceneSpec& s, const std::array<double, 3>& g) { s.gravity = Vec3(g[0], g[1], g[2]); })
      .def(
          "add",
          [](SceneSpec& s, const std::string& tag, const py::kwargs& attributes) {
            ElementSpec& element = s.add(tag);
            for (const auto& [key, value] : attributes) {
              const std::string name = py::str(key).cast<std::string>();
              element.set(name, attributeOf(name, value));
            }
          },
          py::arg("tag"),
          "Append an element with the XML format's tag and attributes (docs/scene-format.md), e.g. "
          "scene.add('mass', name='m1', mass=1.0, position=(1, 0, 0))");

  module.def("run", &run, py::arg("scene"), py::kw_only(), py::arg("integrator") = "", py::arg("dt") = py::none(),
             py::arg("t_end") = py::none(), py::arg("out") = "", py::arg("output_interval") = py::none(),
             py::arg("adaptive") = false, py::arg("rtol") = py::none(), py::arg("atol") = py::none(),
             py::arg("max_order") = py::none(), py::arg("sundials_klu") = false, py::arg("dt_out") = py::none(),
             py::arg("checkpoint_every") = 0, py::arg("restart") = "", py::arg("budget") = false,
             py::arg("urdf_limits") = false,
             "Run a scene file (str or path) or a Scene with the options of `metriplex run` (docs/library.md). "
             "Writes files only into `out` when given. Raises InputError (a ValueError) on invalid input.");
}
