// The Python module `motes` (pybind11): scenes from files or dicts, devices, simulations on any
// backend, state as numpy arrays (copies), body velocities, the frame writers. motes's errors
// come back as motes.Error (a RuntimeError) with motes's own message. docs/python.md.
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include <cstdint>
#include <filesystem>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "motes/devices.h"
#include "motes/output.h"
#include "motes/scene.h"
#include "motes/simulation.h"

namespace py = pybind11;

namespace {

/// motes.Error, raised for every motes::Status that is not ok. Made once and never freed: it
/// must outlive the interpreter's own teardown of the module.
py::object& error_type() {
  static auto* type = new py::object();
  return *type;
}

[[noreturn]] void raise(const std::string& message) {
  PyErr_SetString(error_type().ptr(), message.c_str());
  throw py::error_already_set();
}

void check(const motes::Status& s) {
  if (!s) raise(s.message());
}

template <typename T>
T take(motes::Result<T> r) {
  if (!r) raise(r.message());
  return std::move(r).value();
}

/// A (rows, columns) float32 array of the first `columns` components of each vec4 (a copy).
py::array_t<float> columns_of(const std::vector<motes::shared::vec4>& v, int columns) {
  py::array_t<float> out({static_cast<py::ssize_t>(v.size()), static_cast<py::ssize_t>(columns)});
  auto m = out.mutable_unchecked<2>();
  for (std::size_t i = 0; i < v.size(); ++i) {
    const float c[4] = {v[i].x, v[i].y, v[i].z, v[i].w};
    for (int k = 0; k < columns; ++k) m(static_cast<py::ssize_t>(i), k) = c[k];
  }
  return out;
}

/// The w component of each vec4 as a float32 vector (a copy).
py::array_t<float> w_of(const std::vector<motes::shared::vec4>& v) {
  py::array_t<float> out(static_cast<py::ssize_t>(v.size()));
  auto m = out.mutable_unchecked<1>();
  for (std::size_t i = 0; i < v.size(); ++i) m(static_cast<py::ssize_t>(i)) = v[i].w;
  return out;
}

/// Rows of a (n, 3) array-like as vectors; an error names `what` and the shape it got.
std::vector<Eigen::Vector3d> vectors_of(const py::object& obj, std::size_t n, const char* what) {
  auto a = py::array_t<double, py::array::c_style | py::array::forcecast>::ensure(obj);
  if (!a || a.ndim() != 2 || a.shape(1) != 3 || static_cast<std::size_t>(a.shape(0)) != n) {
    raise(std::string(what) + ": expected an array of shape (" + std::to_string(n) + ", 3)");
  }
  auto r = a.unchecked<2>();
  std::vector<Eigen::Vector3d> out(n);
  for (std::size_t i = 0; i < n; ++i) {
    const auto k = static_cast<py::ssize_t>(i);
    out[i] = Eigen::Vector3d(r(k, 0), r(k, 1), r(k, 2));
  }
  return out;
}

/// A simulation and the last snapshot read (each accessor reads the device once per step).
class PySimulation {
 public:
  PySimulation(const motes::Scene& scene, const std::string& backend, int device, int threads) {
    motes::DeviceOptions options;
    options.cpu_threads = threads;
    auto opened = take(motes::open_device(backend, device, options));
    sim_ = take(motes::Simulation::create(scene, std::move(opened)));
  }

  void step(std::uint64_t count) {
    motes::Status s;
    {
      py::gil_scoped_release release;  // other Python threads run while the device steps
      s = sim_->step(count);
    }
    check(s);
  }

  const motes::Snapshot& state() {
    if (!snap_ || snap_->step != sim_->steps()) snap_ = take(sim_->snapshot());
    return *snap_;
  }
  void forget() { snap_.reset(); }

  motes::Simulation& sim() { return *sim_; }

 private:
  std::unique_ptr<motes::Simulation> sim_;
  std::optional<motes::Snapshot> snap_;
};

py::dict device_dict(const motes::DeviceInfo& d) {
  py::dict out;
  out["backend"] = d.backend;
  out["index"] = d.index;
  out["name"] = d.name;
  out["detail"] = d.detail;
  return out;
}

}  // namespace

PYBIND11_MODULE(motes, m) {
  m.doc() =
      "motes: particle-based physics on OpenMP, CUDA and Vulkan. Arrays returned are copies of "
      "the state; errors are motes.Error with motes's message.";
  error_type() = py::exception<std::runtime_error>(m, "Error", PyExc_RuntimeError);
  m.attr("__version__") = MOTES_VERSION;

  py::class_<motes::Scene>(m, "Scene", "A loaded, validated scene (motes.load_scene)")
      .def_readonly("source", &motes::Scene::source)
      .def_property_readonly("particle_count", &motes::Scene::particle_count)
      .def_property_readonly("body_count", [](const motes::Scene& s) { return s.bodies.size(); })
      .def_property_readonly("dt", [](const motes::Scene& s) { return s.settings.dt; })
      .def("__repr__", [](const motes::Scene& s) {
        return "<motes.Scene " + s.source + ": " + std::to_string(s.bodies.size()) + " bodies, " +
               std::to_string(s.particle_count()) + " particles>";
      });

  m.def(
      "load_scene",
      [](const py::object& source, const std::string& base_dir) {
        if (py::isinstance<py::dict>(source)) {
          // A dict: the same JSON the file would hold (docs/scene-format.md).
          const std::string text =
              py::module_::import("json").attr("dumps")(source).cast<std::string>();
          const std::string dir =
              base_dir.empty() ? std::filesystem::current_path().string() : base_dir;
          return take(motes::load_scene_text(text, "<dict>", dir));
        }
        return take(
            motes::load_scene_file(py::str(py::module_::import("os").attr("fspath")(source))));
      },
      py::arg("source"), py::arg("base_dir") = "",
      "Loads a scene from a JSON file (a path) or from a dict with the same keys; relative mesh "
      "paths of a dict resolve from base_dir (default: the current directory).");

  m.def(
      "default_scene", [] { return take(motes::builtin_default_scene()); },
      "The built-in default scene (examples/scenes/dominoes.json).");

  m.def(
      "devices",
      [] {
        py::list out;
        for (const motes::BackendReport& r : motes::list_backends()) {
          py::dict b;
          b["backend"] = r.backend;
          b["compiled"] = r.compiled;
          py::list devs;
          for (const motes::DeviceInfo& d : r.devices) devs.append(device_dict(d));
          b["devices"] = devs;
          b["unavailable_reason"] = r.unavailable_reason;
          out.append(b);
        }
        return out;
      },
      "Every backend motes knows, with its devices or why it has none.");

  py::class_<PySimulation>(m, "Simulation", "A scene running on one device")
      .def(py::init<const motes::Scene&, const std::string&, int, int>(), py::arg("scene"),
           py::arg("backend") = "auto", py::arg("device") = -1, py::arg("threads") = 0,
           "backend: 'auto', 'openmp', 'cuda' or 'vulkan'; device: its index (-1: default); "
           "threads: OpenMP threads (0: OpenMP's default).")
      .def("step", &PySimulation::step, py::arg("count") = 1, "Advances count steps of dt.")
      .def_property_readonly("time", [](PySimulation& s) { return s.sim().time(); })
      .def_property_readonly("steps", [](PySimulation& s) { return s.sim().steps(); })
      .def_property_readonly("particle_count",
                             [](PySimulation& s) { return s.sim().particle_count(); })
      .def_property_readonly("body_count", [](PySimulation& s) { return s.sim().body_count(); })
      .def_property_readonly("device",
                             [](PySimulation& s) { return device_dict(s.sim().device().info()); })
      .def_property_readonly("body_names",
                             [](PySimulation& s) {
                               std::vector<std::string> names;
                               for (const motes::BodyInfo& b : s.sim().bodies())
                                 names.push_back(b.name);
                               return names;
                             })
      .def_property_readonly(
          "body_kinds",
          [](PySimulation& s) {
            // What each body is, in body_names' order: "rigid", "static", "free sphere", "soft",
            // "cloth or rope" or "fluid".
            std::vector<std::string> kinds;
            for (const motes::BodyInfo& b : s.sim().bodies()) {
              kinds.emplace_back(b.fluid                             ? "fluid"
                                 : b.linked                          ? "cloth or rope"
                                 : b.soft                            ? "soft"
                                 : b.free_sphere                     ? "free sphere"
                                 : b.kind == motes::BodyKind::Static ? "static"
                                                                     : "rigid");
            }
            return kinds;
          },
          "What each body is, in body_names' order: rigid, static, free sphere, soft, cloth or "
          "rope, fluid.")
      .def(
          "positions", [](PySimulation& s) { return columns_of(s.state().particle_pos, 3); },
          "Particle centres, (N, 3) float32 (a copy).")
      .def(
          "velocities", [](PySimulation& s) { return columns_of(s.state().particle_vel, 3); },
          "Particle velocities, (N, 3) float32.")
      .def(
          "radii", [](PySimulation& s) { return w_of(s.state().particle_pos); },
          "Particle radii, (N,) float32.")
      .def(
          "particle_bodies",
          [](PySimulation& s) {
            const auto& b = s.state().particle_body;
            return py::array_t<std::uint32_t>(static_cast<py::ssize_t>(b.size()), b.data());
          },
          "Body index of each particle, (N,) uint32.")
      .def(
          "body_positions", [](PySimulation& s) { return columns_of(s.state().body_pos, 3); },
          "Centres of mass, (B, 3) float32.")
      .def(
          "body_orientations", [](PySimulation& s) { return columns_of(s.state().body_quat, 4); },
          "Orientations as quaternions (x, y, z, w), body frame to world, (B, 4) float32.")
      .def(
          "body_velocities", [](PySimulation& s) { return columns_of(s.state().body_vel, 3); },
          "Velocities of the centres of mass, (B, 3) float32.")
      .def(
          "body_angular_velocities",
          [](PySimulation& s) { return columns_of(s.state().body_angvel, 3); },
          "Angular velocities in world axes, (B, 3) float32.")
      .def(
          "set_body_velocities",
          [](PySimulation& s, const py::object& velocity, const py::object& angular) {
            const std::size_t n = s.sim().body_count();
            const auto v = vectors_of(velocity, n, "velocity");
            const auto w = angular.is_none() ? std::vector<Eigen::Vector3d>{}
                                             : vectors_of(angular, n, "angular");
            s.forget();
            check(s.sim().set_body_velocities(v, w));
          },
          py::arg("velocity"), py::arg("angular") = py::none(),
          "Sets every body's velocity, (B, 3), and angular velocity, (B, 3) or None (keep).")
      .def(
          "state_hash", [](PySimulation& s) { return take(s.sim().state_hash()); },
          "64-bit hash of the whole state: the same as `motes run` prints for the same run.")
      .def("check_finite", [](PySimulation& s) { check(s.sim().check_finite()); })
      .def(
          "check_motion",
          [](PySimulation& s) {
            const motes::MotionReport r = take(s.sim().check_motion());
            py::dict out;
            out["moving"] = r.moving;
            out["travel"] = r.travel;
            out["speed"] = r.speed;
            out["diameter"] = r.diameter;
            out["body"] = r.body;
            out["particle"] = r.particle;
            out["safe_dt"] = r.safe_dt;
            out["warning"] = r.warning;
            out["kinetic_energy"] = r.kinetic_energy;
            out["potential_energy"] = r.potential_energy;
            out["energy"] = r.energy;
            out["energy0"] = r.reference.energy();
            out["contact_energy0"] = r.reference.contact;
            out["reference_step"] = r.reference.step;
            out["margin"] = r.reference.margin_at(r.kinetic_energy);
            out["rise"] = r.rise;
            out["largest_rise"] = r.largest_rise;
            out["largest_kinetic"] = r.largest_kinetic;
            const auto index = [](std::uint32_t i) -> py::object {
              if (i == motes::MechanicalEnergy::kNone) return py::none();
              return py::int_(i);
            };
            out["largest_kinetic_body"] = index(r.largest_kinetic_body);
            out["largest_kinetic_particle"] = index(r.largest_kinetic_particle);
            out["speed_limit"] = r.speed_limit;
            return out;
          },
          "The motion and energy guards (docs/reliability.md): the fastest particle's travel per "
          "substep (in diameters), speed, diameter, body, particle and the largest safe dt, with "
          "a tunnelling warning past a quarter diameter; the scene's kinetic and potential energy "
          "(J) against the reference taken at the first check (or the first after "
          "set_body_velocities): energy0 (its stored contact "
          "energy included), the margin, the rise above energy0 now and the largest since, the "
          "body (and particle, None for a rigid body) with the most kinetic energy, and the "
          "speed no particle may exceed. Raises on a NaN, on energy more than the margin above "
          "energy0, and on a particle faster than that energy allows.");

  py::class_<motes::FrameWriter>(m, "FrameWriter", "Output files of the frames of a run")
      .def(py::init([](const std::string& directory, const std::string& format,
                       std::vector<std::string> body_names) {
             const motes::OutputFormat f = take(motes::parse_output_format(format));
             return take(motes::open_frame_writer(f, directory, std::move(body_names)));
           }),
           py::arg("directory"), py::arg("format") = "vtu",
           py::arg("body_names") = std::vector<std::string>{},
           "format: 'vtu' (particles.pvd, bodies.pvd and their frames) or 'csv' (particles.csv, "
           "bodies.csv), as `motes run` writes them (docs/cli.md).")
      .def(
          "write", [](motes::FrameWriter& w, PySimulation& s) { check(w.write_frame(s.state())); },
          py::arg("simulation"), "Writes the simulation's current state as the next frame.")
      .def("close", [](motes::FrameWriter& w) { check(w.finish()); })
      .def_property_readonly("frames", &motes::FrameWriter::frames)
      .def_property_readonly("main_path", &motes::FrameWriter::main_path);
}
