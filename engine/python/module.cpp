// rm3d._rm3d: the Python binding of the public engine API (engine/api/rm3d/simulation.h). The
// agents' arrays are numpy views over the engine's buffers (no copy per step); stepping releases
// the GIL. docs/python.md is the guide; engine/python/rm3d/ holds the pure-Python parts.
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include <cmath>
#include <cstdint>
#include <cstring>
#include <memory>
#include <optional>

#include "rm3d/simulation.h"

namespace py = pybind11;
using rm3d::api::AgentArrays;
using rm3d::api::Batch;
using rm3d::api::Error;
using rm3d::api::Options;
using rm3d::api::Simulation;
using rm3d::api::View;

namespace {

/// A params dict as `--param k=v` strings: str, int, float (repr: every bit) or bool.
std::map<std::string, std::string> toParams(const py::object& params, const char* arg = "params") {
  std::map<std::string, std::string> out;
  if (params.is_none()) return out;
  if (!py::isinstance<py::dict>(params))
    throw py::type_error(std::string(arg) + ": expected a dict of name -> str, int, float or bool, got " +
                         std::string(py::str(py::type::of(params).attr("__name__"))));
  for (auto [k, v] : py::reinterpret_borrow<py::dict>(params)) {
    if (!py::isinstance<py::str>(k))
      throw py::type_error(std::string(arg) + ": key " + std::string(py::repr(k)) + " is not a str");
    const std::string key = py::cast<std::string>(k);
    if (key.empty() || key.find('=') != std::string::npos)
      throw py::value_error(std::string(arg) + ": key " + std::string(py::repr(k)) +
                            " is not a name (expected letters, digits, _ and no '=')");
    std::string value;
    if (py::isinstance<py::bool_>(v))
      value = py::cast<bool>(v) ? "true" : "false";
    else if (py::isinstance<py::int_>(v) || py::isinstance<py::str>(v))
      value = py::cast<std::string>(py::str(v));
    else if (py::isinstance<py::float_>(v)) {
      const double d = py::cast<double>(v);
      if (!std::isfinite(d))
        throw py::value_error(std::string(arg) + "['" + key + "'] = " + std::string(py::repr(v)) +
                              ": expected a finite number");
      value = py::cast<std::string>(py::repr(v));
    } else
      throw py::type_error(std::string(arg) + "['" + key + "']: expected str, int, float or bool, got " +
                           std::string(py::str(py::type::of(v).attr("__name__"))));
    out[key] = value;
  }
  return out;
}

// A world's seed is a Lua integer (world.set{seed=}, math.randomseed): 0 to 2**63-1, as
// `rm3d run --seed` takes (a larger one was refused by the world script's first line instead).
std::optional<uint64_t> toSeed(const py::object& seed, const char* arg = "seed") {
  if (seed.is_none()) return std::nullopt;
  if (!py::isinstance<py::int_>(seed) || py::isinstance<py::bool_>(seed))
    throw py::type_error(std::string(arg) + ": expected an int from 0 to 2**63-1 or None, got " +
                         std::string(py::str(py::type::of(seed).attr("__name__"))));
  uint64_t v = 0;
  try {
    v = py::cast<uint64_t>(seed);
  } catch (const py::cast_error&) {
    v = UINT64_MAX;
  }
  if (v > uint64_t(INT64_MAX))
    throw py::value_error(std::string(arg) + " = " + std::string(py::repr(seed)) +
                          ": expected 0 to 2**63-1 (a world's seed is a Lua integer, as rm3d run --seed)");
  return v;
}

std::string toPath(const py::object& p, const char* arg = "path") {
  if (py::isinstance<py::str>(p)) return py::cast<std::string>(p);
  if (py::hasattr(p, "__fspath__")) {
    const py::object r = p.attr("__fspath__")();
    if (!py::isinstance<py::str>(r))
      throw py::type_error(std::string(arg) + ": its __fspath__() returned " +
                           std::string(py::str(py::type::of(r).attr("__name__"))) + "; expected a str");
    return py::cast<std::string>(r);
  }
  throw py::type_error(std::string(arg) + ": expected a str or os.PathLike, got " +
                       std::string(py::str(py::type::of(p).attr("__name__"))));
}

py::object jsonLoads(const std::string& text) {
  return py::module_::import("json").attr("loads")(text);
}

/// A numpy view of `data` (shape, C order) that keeps `owner` alive; read-only unless writable.
template <typename T>
py::array view(const std::shared_ptr<AgentArrays>& owner, T* data, std::vector<py::ssize_t> shape,
               bool writable) {
  auto* keep = new std::shared_ptr<AgentArrays>(owner);
  py::capsule base(keep, [](void* p) { delete static_cast<std::shared_ptr<AgentArrays>*>(p); });
  py::array_t<T> a(shape, data, base);
  if (!writable) a.attr("setflags")(py::arg("write") = false);
  return a;
}

/// Copies a user's action array into `dst` (rows x dim), checking shape and dtype.
void assignActions(py::handle value, double* dst, const std::vector<py::ssize_t>& shape, const char* name) {
  py::array a = py::array::ensure(value);
  if (!a) throw py::type_error(std::string(name) + ": expected a numpy array (or nested lists) of numbers");
  const char kind = a.dtype().kind();
  if (kind != 'f' && kind != 'i' && kind != 'u')
    throw py::type_error(std::string(name) + ": expected a float array, got dtype " +
                         std::string(py::str(a.dtype())));
  std::string want = "(";
  for (size_t i = 0; i < shape.size(); ++i) want += (i ? ", " : "") + std::to_string(shape[i]);
  want += shape.size() == 1 ? ",)" : ")";
  bool same = a.ndim() == py::ssize_t(shape.size());
  for (size_t i = 0; same && i < shape.size(); ++i) same = a.shape(py::ssize_t(i)) == shape[i];
  if (!same) {
    std::string got = "(";
    for (py::ssize_t i = 0; i < a.ndim(); ++i) got += (i ? ", " : "") + std::to_string(a.shape(i));
    got += a.ndim() == 1 ? ",)" : ")";
    throw py::value_error(std::string(name) + ": expected shape " + want + ", got " + got);
  }
  auto d = py::array_t<double, py::array::c_style | py::array::forcecast>::ensure(a);
  std::copy(d.data(), d.data() + d.size(), dst);
}

/// The Python World: a Simulation, or nothing once closed.
struct PyWorld {
  std::unique_ptr<Simulation> sim;
  bool busy = false;  ///< a call runs without the GIL (read and written only under the GIL)
  void checkIdle() const {
    if (busy)
      throw Error("this world is busy: another Python thread is in a call on it (one call at a time)");
  }
  Simulation& s() {
    checkIdle();
    if (!sim || sim->closed()) throw Error("this world is closed");
    return *sim;
  }
  /// Ends the world; while another thread's call runs on it, that is "busy" too (closing under
  /// a running step freed what the step was using).
  void close() {
    checkIdle();
    if (sim) sim->close();
  }
};

/// The Python Batch: a Batch, with the same one-call-at-a-time rule as PyWorld.
struct PyBatch {
  std::unique_ptr<Batch> batch;
  bool busy = false;
  Batch& get() {
    if (busy)
      throw Error("this batch is busy: another Python thread is in a call on it (one call at a time)");
    return *batch;
  }
};

/// Marks an object busy for a call that releases the GIL; declared before the release, so it
/// ends after the GIL is back.
struct BusyGuard {
  bool& flag;
  explicit BusyGuard(bool& f) : flag(f) { flag = true; }
  ~BusyGuard() { flag = false; }
};

Options makeOptions(const py::object& seed, const py::object& params, int threads, bool policy,
                    const py::object& record, bool strict, bool echo, const py::object& root,
                    bool snapshots = true) {
  Options o;
  o.seed = toSeed(seed);
  o.params = toParams(params);
  o.threads = threads;
  o.policy = policy;
  o.strict = strict;
  o.echo = echo;
  o.snapshots = snapshots;
  if (!record.is_none()) o.record = toPath(record, "record");
  if (!root.is_none()) o.root = toPath(root, "root");
  return o;
}

/// Runs f() without the GIL, the object marked busy meanwhile (null: nothing to mark). An Error
/// raised because Ctrl-C interrupted f becomes the KeyboardInterrupt that is pending.
template <class F>
auto withoutGil(bool* busy, F&& f) -> decltype(f()) {
  std::optional<BusyGuard> guard;
  if (busy) guard.emplace(*busy);
  try {
    py::gil_scoped_release release;
    return f();
  } catch (const Error&) {
    if (PyErr_Occurred()) throw py::error_already_set();
    throw;
  }
}

/// Asked between steps while the GIL is released: true (and the Python error left set) when a
/// signal handler raised, so Ctrl-C ends a long step() at a step boundary.
bool askPython() {
  py::gil_scoped_acquire gil;
  return PyErr_CheckSignals() != 0;
}

}  // namespace

PYBIND11_MODULE(_rm3d, m) {
  m.doc() = "RM3D engine binding (see the rm3d package and docs/python.md)";
  static py::exception<Error> error(m, "Error", PyExc_RuntimeError);
  py::register_exception_translator([](std::exception_ptr p) {
    try {
      if (p) std::rethrow_exception(p);
    } catch (const Error& e) {
      error(e.what());
    }
  });

  py::class_<PyWorld>(m, "World", "One world: a world file with a seed and params, stepped from Python.")
      .def(py::init([](const py::object& path, const py::object& seed, const py::object& params, int threads,
                       bool policy, const py::object& record, bool strict, bool echo, const py::object& root,
                       bool snapshots) {
             Options o = makeOptions(seed, params, threads, policy, record, strict, echo, root, snapshots);
             const std::string p = toPath(path);
             py::gil_scoped_release release;
             return PyWorld{Simulation::open(p, o)};
           }),
           py::arg("path"), py::arg("seed") = py::none(), py::arg("params") = py::none(),
           py::arg("threads") = 1, py::kw_only(), py::arg("policy") = false, py::arg("record") = py::none(),
           py::arg("strict") = false, py::arg("echo") = false, py::arg("root") = py::none(),
           py::arg("snapshots") = true,
           "Loads a world file. seed: an int (None: the world's own); params: a dict of str, "
           "int, float or bool, the world script's `args` (as `rm3d run --param k=v`); threads: "
           "behaviour threads; policy: `act` drives the modules before every step and "
           "obs/reward/done are refreshed after it; record: a file to record the episode into "
           "(`rm3d replay` plays it); strict: a module fault stops the world; echo: module logs "
           "and the world's prints go to stderr; root: the project folder (None: found from the "
           "world's path). Raises rm3d.Error naming the file and line when it does not load. snapshots=False "
           "keeps no log of the "
           "inputs (a long policy run then holds no growing memory; snapshot() and fork() raise).")
      .def_static(
          "from_string",
          [](const std::string& source, const py::object& seed, const py::object& params, int threads,
             bool policy, const std::string& name, bool strict, bool echo, const py::object& root) {
            Options o = makeOptions(seed, params, threads, policy, py::none(), strict, echo, root);
            py::gil_scoped_release release;
            return PyWorld{Simulation::fromString(source, name, o)};
          },
          py::arg("source"), py::arg("seed") = py::none(), py::arg("params") = py::none(),
          py::arg("threads") = 1, py::kw_only(), py::arg("policy") = false, py::arg("name") = "world",
          py::arg("strict") = false, py::arg("echo") = false, py::arg("root") = py::none(),
          "A world from world-script source text (`name` is what messages call it); the other arguments as "
          "World().")
      .def_static(
          "from_snapshot",
          [](const py::bytes& b, int threads) {
            std::string bytes = b;
            return withoutGil(nullptr,
                              [&] { return PyWorld{Simulation::fromSnapshot(bytes, threads, askPython)}; });
          },
          py::arg("snapshot"), py::kw_only(), py::arg("threads") = 1,
          "A world rebuilt from snapshot() bytes, in this process or another: from here on it runs bit for "
          "bit as the original would have.")
      .def(
          "step",
          [](PyWorld& w, long long n) {
            Simulation& s = w.s();
            withoutGil(&w.busy, [&] { s.step(n, askPython); });
            if (PyErr_Occurred()) throw py::error_already_set();  // Ctrl-C ended it early
          },
          py::arg("n") = 1,
          "Runs n control steps (the GIL is released). With policy=True each step first applies the `act` "
          "rows (NaN or infinity raises rm3d.Error before any step) and obs/reward/done are refreshed after "
          "the last. A world-script error raises rm3d.Error (file:line). A stopped world does not step.")
      .def_property_readonly(
          "time", [](PyWorld& w) { return w.s().time(); }, "Simulated seconds.")
      .def_property_readonly(
          "steps", [](PyWorld& w) { return w.s().steps(); }, "Control steps run.")
      .def_property_readonly(
          "dt", [](PyWorld& w) { return w.s().dt(); }, "The control step, seconds.")
      .def_property_readonly(
          "path", [](PyWorld& w) { return w.s().path(); },
          "The world file it runs, absolute: the path given, or the data root's when a relative path "
          "is not in the working folder (as rm3d run finds worlds/snake.lua from any folder); '' for "
          "from_string.")
      .def_property_readonly(
          "finished", [](PyWorld& w) { return w.s().finished(); },
          "True once the world stopped (world.stop(), a fatal fault, an error), reached its duration, or "
          "finish() ran. step() goes on past the duration when asked (as rm3d run --seconds); a stopped "
          "world does not step.")
      .def_property_readonly(
          "modules", [](PyWorld& w) { return w.s().moduleNames(); },
          "Module names, in module order (the rows of the arrays).")
      .def_property_readonly(
          "metrics", [](PyWorld& w) { return w.s().metrics(); },
          "The world.metric(name, value) results: a dict.")
      .def_property_readonly(
          "faults", [](PyWorld& w) { return w.s().faults(); },
          "Modules that faulted: a dict name -> message (file:line).")
      .def(
          "summary", [](PyWorld& w) { return jsonLoads(w.s().summaryJson()); },
          "The state now as the dict `rm3d run --json` writes (positions, joints, docks, connections, "
          "events, messages, failures, metrics); the on_end hooks have not run.")
      .def(
          "finish", [](PyWorld& w) { return jsonLoads(w.s().finish()); },
          "Runs the world's on_end hooks (once) and returns the final summary, as `rm3d run --json` writes "
          "it (plus `warnings`: hooks that never ran). The world then no longer steps.")
      .def_property_readonly(
          "obs",
          [](PyWorld& w) {
            auto a = w.s().arrays();
            return view(a, a->obs.data(), {a->rows, a->obsDim}, false);
          },
          "float64 (modules, obs_dim), read-only, a view of the engine's buffer: each module's observe() "
          "row, or its joint angles, joint velocities and dock engaged flags; zero past obs_size.")
      .def_property(
          "act",
          [](PyWorld& w) {
            auto a = w.s().arrays();
            return view(a, a->act.data(), {a->rows, a->actDim}, true);
          },
          [](PyWorld& w, py::handle v) {
            auto a = w.s().arrays();
            assignActions(v, a->act.data(), {a->rows, a->actDim}, "act");
          },
          "float64 (modules, act_dim), writable view: each module's action row, given to its act(a) "
          "(act_size numbers) or, without one, its joints' servo targets (rad). Assigning an array checks "
          "shape and dtype.")
      .def_property_readonly(
          "reward",
          [](PyWorld& w) {
            auto a = w.s().arrays();
            return view(a, a->reward.data(), {a->rows}, false);
          },
          "float64 (modules,): what world.reward(fn) returned (zeros without it).")
      .def_property_readonly(
          "done",
          [](PyWorld& w) {
            auto a = w.s().arrays();
            auto* d = reinterpret_cast<bool*>(a->done.data());
            return view(a, d, {a->rows}, false);
          },
          "bool (modules,): what world.done(fn) returned (False without it).")
      .def_property_readonly(
          "obs_size",
          [](PyWorld& w) {
            auto a = w.s().arrays();
            return view(a, a->obsSize.data(), {a->rows}, false);
          },
          "int32 (modules,): the numbers each obs row holds.")
      .def_property_readonly(
          "act_size",
          [](PyWorld& w) {
            auto a = w.s().arrays();
            return view(a, a->actSize.data(), {a->rows}, false);
          },
          "int32 (modules,): the numbers each act row takes.")
      .def(
          "render",
          [](PyWorld& w, int width, int height, const py::object& camera) {
            View view;
            if (!camera.is_none()) {
              if (!py::isinstance<py::dict>(camera))
                throw Error("render: camera must be a dict with any of eye, target, fov; got " +
                            std::string(py::str(py::type::of(camera).attr("__name__"))));
              for (const auto& [k, v] : camera.cast<py::dict>()) {
                const std::string key = py::str(k);
                auto three = [&](const char* what) {
                  std::vector<double> a;
                  try {
                    a = v.cast<std::vector<double>>();
                  } catch (const py::cast_error&) {
                  }
                  if (a.size() != 3)
                    throw Error(std::string("render: camera ") + what +
                                ": expected three numbers (x, y, z in metres)");
                  return std::array<double, 3>{a[0], a[1], a[2]};
                };
                if (key == "eye")
                  view.eye = three("eye");
                else if (key == "target")
                  view.target = three("target");
                else if (key == "fov") {
                  try {
                    view.fovDeg = v.cast<double>();
                  } catch (const py::cast_error&) {
                    throw Error("render: camera fov: expected a number (degrees)");
                  }
                } else
                  throw Error("render: camera: unknown key '" + key + "' (expected eye, target or fov)");
              }
            }
            Simulation& s = w.s();
            std::vector<uint8_t> rgb = withoutGil(&w.busy, [&] { return s.render(width, height, view); });
            py::array_t<uint8_t> out({py::ssize_t(height), py::ssize_t(width), py::ssize_t(3)});
            std::memcpy(out.mutable_data(), rgb.data(), rgb.size());
            return out;
          },
          py::arg("width") = 640, py::arg("height") = 480, py::kw_only(), py::arg("camera") = py::none(),
          "The world now as a picture: a (height, width, 3) uint8 array, RGB, drawn offscreen as `rm3d run "
          "--png` draws it (no display needed). camera: a dict with any of eye=(x, y, z), target=(x, y, z) "
          "(metres) and fov (degrees); what it leaves out, world.camera{} or the automatic camera gives. "
          "The automatic camera frames the world as first rendered and keeps that frame.")
      .def(
          "snapshot",
          [](PyWorld& w) {
            Simulation& s = w.s();
            return py::bytes(withoutGil(&w.busy, [&] { return s.snapshot(); }));
          },
          "The run so far as bytes (its world, Lua texts, seed, params and inputs); restore() or "
          "World.from_snapshot() re-run it to this step, bit for bit.")
      .def(
          "restore",
          [](PyWorld& w, const py::bytes& b) {
            std::string bytes = b;
            Simulation& s = w.s();
            withoutGil(&w.busy, [&] { s.restore(bytes, askPython); });
          },
          "Makes this world the snapshot's (rebuilt and re-run to its step). Damaged bytes raise rm3d.Error "
          "and leave the world as it was.")
      .def(
          "fork",
          [](PyWorld& w) {
            Simulation& s = w.s();
            return withoutGil(&w.busy, [&] { return PyWorld{s.fork(askPython)}; });
          },
          "An independent copy of this world at this step.")
      .def(
          "close", [](PyWorld& w) { w.close(); },
          "Ends the recording (if any); later calls raise rm3d.Error. Also on leaving a `with` block.")
      .def_property_readonly(
          "closed", [](PyWorld& w) { return !w.sim || w.sim->closed(); }, "True after close().")
      .def("__enter__", [](PyWorld& w) -> PyWorld& { return w; })
      .def("__exit__", [](PyWorld& w, py::args) { w.close(); });

  py::class_<PyBatch>(m, "Batch", "Many worlds stepped together by C++ threads (GIL released).")
      .def(py::init([](const py::object& paths, const py::object& seeds, const py::object& params,
                       int threads, bool policy, bool strict, const py::object& root) {
             std::vector<std::string> ps;
             const bool one = py::isinstance<py::str>(paths) || py::hasattr(paths, "__fspath__");
             if (!one) {
               if (!py::isinstance<py::sequence>(paths))
                 throw py::type_error("paths: expected a path or a list of paths");
               for (auto p : paths) ps.push_back(toPath(py::reinterpret_borrow<py::object>(p), "paths[i]"));
             }
             std::vector<py::object> sd, pr;
             if (!seeds.is_none()) {
               if (!py::isinstance<py::sequence>(seeds) || py::isinstance<py::str>(seeds))
                 throw py::type_error("seeds: expected a list of ints (one per world) or None");
               for (auto s : seeds) sd.push_back(py::reinterpret_borrow<py::object>(s));
             }
             if (!params.is_none() && !py::isinstance<py::dict>(params)) {
               if (!py::isinstance<py::sequence>(params) || py::isinstance<py::str>(params))
                 throw py::type_error("params: expected a dict, or a list of dicts (one per world)");
               for (auto p : params) pr.push_back(py::reinterpret_borrow<py::object>(p));
             }
             size_t n = one ? 1 : ps.size();
             if (one) n = std::max({sd.size(), pr.size(), size_t(1)});
             if (one) ps.assign(n, toPath(paths));
             auto count = [&](const char* what, size_t k) {
               if (k != 0 && k != n)
                 throw py::value_error(std::string(what) + ": " + std::to_string(k) + " given for " +
                                       std::to_string(n) + " worlds; expected one per world");
             };
             count("seeds", sd.size());
             count("params", pr.size());
             if (n == 0) throw py::value_error("paths: empty; expected at least one world");
             std::vector<Options> opts(n);
             for (size_t i = 0; i < n; ++i) {
               const py::object p = pr.empty() ? params : pr[i];
               opts[i] = makeOptions(sd.empty() ? py::none() : sd[i], p, 1, policy, py::none(), strict, false,
                                     root);
             }
             py::gil_scoped_release release;
             return PyBatch{std::make_unique<Batch>(ps, opts, threads)};
           }),
           py::arg("paths"), py::arg("seeds") = py::none(), py::arg("params") = py::none(),
           py::arg("threads") = 1, py::kw_only(), py::arg("policy") = false, py::arg("strict") = false,
           py::arg("root") = py::none(),
           "Many worlds: paths is one path (the batch then has len(seeds) or len(params) worlds) "
           "or a list of paths; seeds a list of ints and params one dict or a list of dicts, one "
           "per world. `threads` C++ threads step whole worlds, each alone on one thread, so "
           "results do not depend on the count.")
      .def("__len__", [](PyBatch& pb) { return pb.get().size(); })
      .def_property_readonly(
          "size", [](PyBatch& pb) { return pb.get().size(); }, "The number of worlds.")
      .def(
          "step",
          [](PyBatch& pb, long long n) {
            Batch& b = pb.get();
            withoutGil(&pb.busy, [&] { b.step(n, askPython); });
            if (PyErr_Occurred()) throw py::error_already_set();  // Ctrl-C ended it early
          },
          py::arg("n") = 1,
          "Every world that has not stopped runs n steps (policy: the act rows each step); errors raise "
          "rm3d.Error naming the world after every world has stepped.")
      .def(
          "reset",
          [](PyBatch& pb, const py::object& mask) {
            Batch& b = pb.get();
            std::vector<uint8_t> mk;
            if (!mask.is_none()) {
              auto a = py::array::ensure(mask);
              if (!a || a.ndim() != 1 || a.shape(0) != b.size())
                throw py::value_error("mask: expected a bool array of shape (" + std::to_string(b.size()) +
                                      ",)");
              auto d = py::array_t<bool, py::array::c_style | py::array::forcecast>::ensure(a);
              mk.assign(d.data(), d.data() + d.size());
            }
            withoutGil(&pb.busy, [&] { b.reset(mk); });
          },
          py::arg("mask") = py::none(),
          "Starts the worlds where mask (bool, one per world; None: all) is True again from their files, "
          "seeds and params.")
      .def_property_readonly(
          "obs",
          [](PyBatch& pb) {
            Batch& b = pb.get();
            auto a = b.arrays();
            return view(a, a->obs.data(), {b.size(), b.maxModules(), a->obsDim}, false);
          },
          "float64 (worlds, max modules, obs_dim), read-only view.")
      .def_property(
          "act",
          [](PyBatch& pb) {
            Batch& b = pb.get();
            auto a = b.arrays();
            return view(a, a->act.data(), {b.size(), b.maxModules(), a->actDim}, true);
          },
          [](PyBatch& pb, py::handle v) {
            Batch& b = pb.get();
            auto a = b.arrays();
            assignActions(v, a->act.data(), {b.size(), b.maxModules(), a->actDim}, "act");
          },
          "float64 (worlds, max modules, act_dim), writable view.")
      .def_property_readonly(
          "reward",
          [](PyBatch& pb) {
            Batch& b = pb.get();
            auto a = b.arrays();
            return view(a, a->reward.data(), {b.size(), b.maxModules()}, false);
          },
          "float64 (worlds, max modules).")
      .def_property_readonly(
          "done",
          [](PyBatch& pb) {
            Batch& b = pb.get();
            auto a = b.arrays();
            return view(a, reinterpret_cast<bool*>(a->done.data()), {b.size(), b.maxModules()}, false);
          },
          "bool (worlds, max modules).")
      .def_property_readonly(
          "mask",
          [](PyBatch& pb) {
            Batch& b = pb.get();
            auto a = b.arrays();
            return view(a, reinterpret_cast<bool*>(a->mask.data()), {b.size(), b.maxModules()}, false);
          },
          "bool (worlds, max modules): True where the row is a module of that world.")
      .def_property_readonly(
          "obs_size",
          [](PyBatch& pb) {
            Batch& b = pb.get();
            auto a = b.arrays();
            return view(a, a->obsSize.data(), {b.size(), b.maxModules()}, false);
          },
          "int32 (worlds, max modules).")
      .def_property_readonly(
          "act_size",
          [](PyBatch& pb) {
            Batch& b = pb.get();
            auto a = b.arrays();
            return view(a, a->actSize.data(), {b.size(), b.maxModules()}, false);
          },
          "int32 (worlds, max modules).")
      .def_property_readonly(
          "time",
          [](PyBatch& pb) {
            Batch& b = pb.get();
            py::array_t<double> t(b.size());
            for (int i = 0; i < b.size(); ++i) t.mutable_at(i) = b.world(i).time();
            return t;
          },
          "float64 (worlds,): each world's simulated seconds.")
      .def_property_readonly(
          "finished",
          [](PyBatch& pb) {
            Batch& b = pb.get();
            py::array_t<bool> t(b.size());
            for (int i = 0; i < b.size(); ++i) t.mutable_at(i) = b.world(i).finished();
            return t;
          },
          "bool (worlds,): World.finished of each.")
      .def_property_readonly(
          "metrics",
          [](PyBatch& pb) {
            Batch& b = pb.get();
            py::list out;
            for (int i = 0; i < b.size(); ++i) out.append(py::cast(b.world(i).metrics()));
            return out;
          },
          "A list of dicts: each world's metrics.")
      .def(
          "summaries",
          [](PyBatch& pb) {
            Batch& b = pb.get();
            py::list out;
            for (int i = 0; i < b.size(); ++i) out.append(jsonLoads(b.world(i).summaryJson()));
            return out;
          },
          "A list of dicts: each world's summary now (as World.summary()).")
      .def(
          "snapshot", [](PyBatch& pb, int i) { return py::bytes(pb.get().world(i).snapshot()); },
          py::arg("i"), "World i's snapshot (World.from_snapshot() makes it a World of its own).")
      .def(
          "close", [](PyBatch& pb) { pb.get().close(); }, "Closes every world; later calls raise rm3d.Error.")
      .def("__enter__", [](PyBatch& pb) -> PyBatch& { return pb; })
      .def("__exit__", [](PyBatch& pb, py::args) { pb.get().close(); });

  m.def(
      "_evaluate",
      [](const py::object& path, const py::list& runs, double seconds, int threads, const std::string& metric,
         const py::object& root) {
        std::vector<Options> opts;
        for (auto r : runs) {
          auto t = py::reinterpret_borrow<py::tuple>(r);
          opts.push_back(makeOptions(t[0], t[1], 1, false, py::none(), false, false, root));
        }
        const std::string p = toPath(path);
        std::vector<std::string> errors;
        std::vector<double> out;
        {
          py::gil_scoped_release release;
          out = rm3d::api::evaluate(p, opts, seconds, threads, metric, &errors);
        }
        return py::make_tuple(py::array_t<double>(py::ssize_t(out.size()), out.data()), errors);
      },
      py::arg("path"), py::arg("runs"), py::arg("seconds"), py::arg("threads"), py::arg("metric"),
      py::arg("root") = py::none());
}
