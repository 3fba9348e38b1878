// RM3D's public engine API: what a program embedding the engine sees (the Python package
// `rm3d` is built on it: engine/python/). Nothing here exposes the World's internals: a
// Simulation is made from a world file or source with a seed and params, stepped, read (time,
// modules, the summary, metrics, the agents' arrays), snapshotted and restored. Errors are
// rm3d::api::Error carrying RM3D's own message ("file:line: ..."). docs/python.md is the guide.
#pragma once

#include <array>
#include <cstdint>
#include <functional>
#include <map>
#include <memory>
#include <optional>
#include <stdexcept>
#include <string>
#include <vector>

namespace rm3d {
class MeshCache;  // assets/mesh_loader.h: opaque here
}

namespace rm3d::api {

/// Bad input (a world that does not load, a world-script error, bad arguments, NaN actions, a
/// call after close): the message is RM3D's, naming the file and line or the argument.
class Error : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

struct Options {
  std::optional<uint64_t> seed;               ///< overrides world.set{seed=}; none: the world's own
  std::map<std::string, std::string> params;  ///< the world script's `args` (as `run --param k=v`)
  int threads = 1;                            ///< behaviour worker threads of this world
  /// The agents' actions drive the modules: before every step the `act` rows go to the
  /// behaviours' act(a) (or the joints' servo targets), and obs, reward and done are refreshed
  /// after it. Off: Lua controls alone; the arrays are refreshed when read.
  bool policy = false;
  bool strict = false;  ///< a module fault stops the world (as `run --strict`)
  /// Keep the inputs snapshot() needs (the actions, 8 bytes per number per step). Off: a long
  /// policy run holds no log, and snapshot()/fork() raise Error.
  bool snapshots = true;
  std::string record;  ///< a recording file (as `run --record`; empty: none)
  bool echo = false;   ///< module log lines and the world's prints go to stderr
  /// The project root (assets/modules, lua/, behaviors/). Empty: $RM3D_ROOT, else the nearest
  /// folder above the world holding assets/modules, else above the working folder, else the
  /// installed data (share/rm3d above this library), else the source tree it was built from.
  std::string root;
};

/// The agents' arrays of one world (or of a batch: rows of every world, world after world):
/// row-major, `rows` x dim, padded with zeros past each row's own size. Held by shared_ptr so a
/// view (a numpy array) keeps them alive; a change of shape makes new arrays.
struct AgentArrays {
  int rows = 0, obsDim = 0, actDim = 0;
  std::vector<double> obs, act, reward;
  std::vector<uint8_t> done, mask;        ///< mask: 1 where the row is a module
  std::vector<int32_t> obsSize, actSize;  ///< the numbers each row uses
};

/// Where a picture is taken from (render): what is given wins over world.camera{...}, as
/// `rm3d run --eye/--target/--fov` do; what is not, the automatic camera chooses.
struct View {
  std::optional<std::array<double, 3>> eye, target;  ///< metres, world frame
  std::optional<double> fovDeg;                      ///< vertical field of view, degrees
};

class Simulation {
 public:
  /// Loads a world file, found as `rm3d run` finds it: the path as given, else (relative and not
  /// in the working folder) in the data root, so "worlds/snake.lua" runs from any folder. Throws
  /// Error.
  static std::unique_ptr<Simulation> open(const std::string& path, const Options& options);
  /// Loads world-script source held in memory (`name` is what messages call it).
  static std::unique_ptr<Simulation> fromString(const std::string& source, const std::string& name,
                                                const Options& options);
  /// A world rebuilt from snapshot() bytes (in this process or another): bit-identical from here.
  /// `interrupted`, when given, is asked every 64 steps of the re-run: true stops it (Error).
  static std::unique_ptr<Simulation> fromSnapshot(const std::string& bytes, int threads = 1,
                                                  const std::function<bool()>& interrupted = {});
  ~Simulation();
  Simulation(const Simulation&) = delete;
  Simulation& operator=(const Simulation&) = delete;

  /// n control steps (`interrupted`, when given, is asked every 64 steps: true ends the call early,
  /// at a step boundary, as if n had been smaller). With policy on, each applies the act rows first (NaN or
  /// infinity: Error, before any step). Throws Error when the world script fails. A world that stopped
  /// (world.stop(), a fatal fault, an error) does not step; one past its duration goes on.
  void step(int64_t n = 1, const std::function<bool()>& interrupted = {});
  /// With policy on: raises Error (as step() would) where the act rows hold a NaN or an
  /// infinity, and changes nothing. Batch::step asks every world before any steps.
  void checkActions();
  double time() const;
  int64_t steps() const;
  double dt() const;
  /// The world file it runs (absolute: the one found, see open); empty for fromString.
  const std::string& path() const;
  /// Stopped, failed, or at its duration.
  bool finished() const;
  bool stopped() const;
  int moduleCount() const;
  std::vector<std::string> moduleNames() const;
  /// The `rm3d run --json` summary now (without the on_end hooks), as JSON text.
  std::string summaryJson() const;
  /// Runs the world's on_end hooks once and returns the final summary (as `rm3d run --json`
  /// writes it). Later calls return the summary again without running the hooks.
  std::string finish();
  std::map<std::string, double> metrics() const;
  /// Modules that faulted: name -> fault text.
  std::map<std::string, std::string> faults() const;

  /// The arrays, up to date (refreshed now if the world stepped since). Their `act` is what the
  /// next step applies under policy.
  std::shared_ptr<AgentArrays> arrays();

  /// The world now, drawn offscreen as `rm3d run --png` draws it (OSMesa: no display, no GPU):
  /// width x height x 3 bytes, RGB, top row first. Without a camera in `view` or world.camera{},
  /// the frame is chosen at the first render and kept while the modules stay in it (as a run's
  /// pictures do). Width and height: 1 to 8192, at most 7680 x 4320 pixels in all.
  std::vector<uint8_t> render(int width, int height, const View& view = {});

  /// The whole run so far as bytes (docs/python.md, "Snapshots"): restore re-runs it bit for bit.
  std::string snapshot() const;
  /// Makes this simulation the snapshot's (same as fromSnapshot, in place).
  void restore(const std::string& bytes, const std::function<bool()>& interrupted = {});
  /// An independent copy at this step.
  std::unique_ptr<Simulation> fork(const std::function<bool()>& interrupted = {}) const;
  /// Ends the recording (if any). Later calls other than close() throw Error.
  void close();
  bool closed() const;

  /// For Batch: from now on the arrays are rows [rowOffset, rowOffset + rows) of `target`, with
  /// its dims (this world's must fit: Error otherwise); the rows read so far are copied there.
  /// Null: back to its own.
  void bindArrays(std::shared_ptr<AgentArrays> target, int rowOffset, int rows);
  /// obs_dim, act_dim and module count this world needs.
  int obsDim() const;
  int actDim() const;

  struct Impl;

 private:
  friend class Batch;
  Simulation();
  /// open and fromSnapshot keeping parsed meshes in `meshes` (a Batch's, or this world's across
  /// restores: assets/mesh_loader.h).
  static std::unique_ptr<Simulation> open(const std::string& path, const Options& options,
                                          std::shared_ptr<rm3d::MeshCache> meshes);
  static std::unique_ptr<Simulation> fromSnapshot(const std::string& bytes, int threads,
                                                  const std::function<bool()>& interrupted,
                                                  std::shared_ptr<rm3d::MeshCache> meshes);
  std::unique_ptr<Impl> m;
};

/// Many worlds stepped together by a pool of C++ threads. Worlds may differ (files, params,
/// bodies): the arrays have max(modules) rows per world, with a mask. Results do not depend on
/// the thread count: each world is stepped on one thread, alone.
class Batch {
 public:
  /// One Options per world (their seeds and params), one path per world.
  Batch(const std::vector<std::string>& paths, const std::vector<Options>& options, int threads);
  ~Batch();
  int size() const;
  /// Every world that has not stopped steps n times (with policy, the act rows each step);
  /// `interrupted` as for Simulation::step (asked by the calling thread between rounds).
  void step(int64_t n = 1, const std::function<bool()>& interrupted = {});
  /// Brings the worlds where mask[i] (empty: all) back to their start: each restores the snapshot
  /// taken when it was made (its texts, seed and params then; not the files as they are now). A
  /// world made with snapshots off or a recording is opened again from its file instead.
  void reset(const std::vector<uint8_t>& mask);
  /// rows = size() x maxModules; refreshed now if any world stepped since.
  std::shared_ptr<AgentArrays> arrays();
  int maxModules() const;
  Simulation& world(int i);
  void close();

 private:
  struct Impl;
  std::unique_ptr<Impl> m;
};

/// Whole runs in C++ with the Lua controllers: every options[i] (seed, params) of `path`, run for
/// `seconds` (<= 0: the world's duration) then its on_end hooks; returns the metric's value per
/// run (NaN where the run did not set it or did not load: `errors` gets "run i: message").
std::vector<double> evaluate(const std::string& path, const std::vector<Options>& options, double seconds,
                             int threads, const std::string& metric,
                             std::vector<std::string>* errors = nullptr);

}  // namespace rm3d::api
