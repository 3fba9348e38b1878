---@meta
-- LuaLS definitions of the world-script API (worlds/*.lua, tests/worlds/*.lua). Generated from
-- docs/api/lua_api.lua by docs/api/generate.lua: edit that file, not this one. ctest luals_meta
-- fails when a bound name is missing, api_generated when this file is stale, api_types when a
-- binding returns other types than declared. Reference page: docs/api/lua.md.

---@alias Vec3 {x: number, y: number, z: number, [1]: number, [2]: number, [3]: number}
---@alias Quat {w: number, x: number, y: number, z: number}

---@class ShapeOptions
---@field at? number[] {x, y, z}
---@field rot? number[] {roll, pitch, yaw}
---@field mass? number 0 (default): static
---@field friction? number
---@field rolling_friction? number m: rolling and spinning resistance (default 0.0005 for dynamic bodies)
---@field velocity? number[]

---@class DockSettings
---@field capture? "joint"|"magnet" how a captured dock is drawn in (default joint)
---@field capture_radius? number m (0.03)
---@field capture_angle? number rad (0.5236, 30 deg)
---@field latch_distance? number m (0.004)
---@field latch_angle? number rad (0.0873, 5 deg)
---@field capture_speed? number m/s: the capture joint closes the faces at most this fast (0.05)
---@field capture_turn_speed? number rad/s: ... and turns them at most this fast (1)
---@field capture_force? number N: the most force the capture joint exerts (20)
---@field capture_torque? number N m: the most torque it exerts (1)
---@field capture_time? number s: a capture not latched after this is reported stalled (3)
---@field pull? number N: the magnet's pull (2)
---@field strength? number N: a connection breaks above this force (100)
---@field strength_torque? number N m: ... or above this torque (10)

---@class world
world = {}
---Settings, all optional (seed before the first spawn); `solver` is `"exact"` (default: 1 substep x 15 iterations, 2 x 15 in a world with cloth) or `"pgs"` (default: 4 x 30; substeps and iterations given are kept; see [Physics](../physics.md)); `max_speed`, `max_angular_speed` and `bounds` are the divergence limits; `expect_faults = true` (or a number: exactly that many faulted modules) declares that the world faults modules on purpose, which `rm3d test` otherwise fails.
---@param s {dt: number?, substeps: integer?, gravity: number[]?, seed: integer?, duration: number?, solver: ("pgs"|"exact")?, solver_iterations: integer?, joint_iterations: integer?, erp: number?, max_speed: number?, max_angular_speed: number?, bounds: number?, expect_faults: (boolean|integer)?}
function world.set(s) end
---Infinite plane z = 0.
---@param g? {friction: number?, restitution: number?}
function world.ground(g) end
---Obstacle; mass 0 (default) is static; a dynamic one may start moving, sleeps once still and wakes when touched; `rolling_friction` (m, default 0.0005 for dynamic bodies) resists rolling and spinning; returns a Body.
---@param o ShapeOptions|{size: number[]}
---@return Body
function world.box(o) end
---An obstacle sphere; the other options as `world.box`.
---@param o ShapeOptions|{radius: number}
---@return Body
function world.sphere(o) end
---An obstacle cylinder along its local z; the other options as `world.box`.
---@param o ShapeOptions|{radius: number, length: number}
---@return Body
function world.cylinder(o) end
---A cylinder of `length` along its local z capped by hemispheres: `length + 2 radius` overall.
---@param o ShapeOptions|{radius: number, length: number}
---@return Body
function world.capsule(o) end
---The convex hull of a mesh file (OBJ, STL, ... through assimp); `concave = true`: the mesh's own triangles, static only (level geometry).
---@param o ShapeOptions|{file: string, scale: number?, concave: boolean?}
---@return Body
function world.mesh(o) end
---A cloth (see [Cloth](../environments.md#cloth)): corners in order around the edge; `resolution` nodes along corner 1→2 and 1→4 (2..256 each, at most 65,536; default 16 x 16); `mass` kg of the whole sheet (default 0.1); `stiffness` in (0, 1] (default 0.9); `pinned` corners (1..4) and `pinned_nodes` (1..nx·ny) held fixed in space; `friction` in [0, 1] (default 0.5, times the body's); `thickness` 0.0001..0.1 m (default 0.005); returns a Cloth.
---@param o {corners: number[][], resolution: integer[]?, mass: number?, stiffness: number?, pinned: integer[]?, pinned_nodes: integer[]?, friction: number?, thickness: number?, color: number[]?}
---@return Cloth
function world.cloth(o) end
---Static terrain from a grayscale image (see [Environments](../environments.md)): one sample per pixel, black at `at.z`, white at `at.z + height`, centred on (`at.x`, `at.y`), `size` the extent from the first sample to the last; `image`, `size` and `height` required; returns a Heightfield.
---@param o {image: string, size: number[], height: number, at: number[]?, friction: number?}
---@return Heightfield
function world.heightfield(o) end
---Fills the box with fluid particles on a lattice `spacing` apart (default 0.02 m; the particle radius is half of it; `density` 1000 kg/m³, XSPH `viscosity` 0.01, s_corr `tension` 0.01, `iterations` 3 a step, split over `substeps` (default one per iteration, at most `iterations`), `kernel` radius 1.8 spacings); returns a Particles handle (see [Fluids and debris](../environments.md#fluids-and-debris)); position-based fluids (Macklin and Mueller 2013), coupled both ways with bodies and modules.
---@param o {min: number[], max: number[], spacing: number?, density: number?, viscosity: number?, tension: number?, friction: number?, kinetic_friction: number?, damping: number?, iterations: integer?, substeps: integer?, kernel: number?, max_speed: number?}
---@return Particles
function world.fluid(o) end
---The same with grains (`density` 1600, `friction` 0.6 static, kinetic 0.8 of it, `damping` 0.5 /s, `substeps` 1); at most 2,000,000 particles in a world.
---@param o {min: number[], max: number[], spacing: number?, density: number?, friction: number?, kinetic_friction: number?, damping: number?, iterations: integer?, substeps: integer?, max_speed: number?}
---@return Particles
function world.debris(o) end
---A module of `assets/modules/<type>.lua` (or of a module-type file given by path), its root link at `at` (metres) turned by `rot` (`{roll, pitch, yaw}` in radians, about the fixed x, then y, then z axes) or `quat` (`{w, x, y, z}`, normalised; it wins over `rot`); `fixed = true` holds its root link in place (a base); `joints` is its initial posture, angles in radians by joint name (`{pitch = 0.5}`) or in joint order (`{0.5, 0, -0.3}`), within the joints' limits: the root link is at `at` and the other links follow, and the servos hold that posture until commanded; returns a Module.
---@param type string a module type name or a module-type file
---@param o? {at: number[]?, rot: number[]?, quat: number[]?, name: string?, behavior: string?, params: table?, fixed: boolean?, joints: table<string|integer, number>?, docks: DockSettings?}
---@return Module
function world.spawn(type, o) end
---Dock settings over the module types' for every module spawned after the call (a key left out keeps the type's value; `world.spawn`'s `docks` does the same for one module, over these): `capture` `"joint"` (the default: a capture joint draws the faces together, see [Docking at run time](../physics.md#docking-at-run-time)) or `"magnet"` (a force `pull` at each face), and the dock keys of a module-type file: `capture_radius`, `capture_angle`, `latch_distance`, `latch_angle`, `capture_speed`, `capture_turn_speed`, `capture_force`, `capture_torque`, `capture_time`, `pull`, `strength`, `strength_torque`.
---@param s DockSettings
function world.docks(s) end
---Before the first step: places b (and what is docked to it) so its dock `dock_b` faces a's `dock_a` squarely, `gap` metres (default 0.01) out along a's normal, turned `orientation` x 360/symmetry degrees about it (default 0); nothing is locked (the docks latch at run time if they are within capture; for modules on the ground, then `world.place_on_ground(b)`).
---@param a Module
---@param dock_a string
---@param b Module
---@param dock_b string
---@param gap? number metres between the faces (default 0.01)
---@param orientation? integer turns about the normal (default 0)
function world.place_facing(a, dock_a, b, dock_b, gap, orientation) end
---Before the first step: moves m and everything connected to it straight down (or up) until the lowest point of their collision shapes is at height `z` (default 0, the ground plane); returns how far it moved (m).
---@param m Module
---@param z? number metres (default 0, the ground plane)
---@return number moved metres moved (+ up)
function world.place_on_ground(m, z) end
---Places b (and what is docked to it) so the docks mate face to face, turned `orientation` x 90° about the normal, and locks them; if a and b are already connected another way the docks must already face each other (closing a loop).
---@param a Module
---@param dock_a string
---@param b Module
---@param dock_b string
---@param orientation? integer quarter turns about the normal
function world.connect(a, dock_a, b, dock_b, orientation) end
---Every module, in spawn order.
---@return Module[]
function world.modules() end
---The module with that id or name, or nil.
---@param id_or_name integer|string
---@return Module?
function world.module(id_or_name) end
---The connected components (modules joined by engaged docks), as arrays of Modules.
---@return Module[][]
function world.components() end
---The picture's view; with `follow`, `eye` is an offset from that module.
---@param c {eye: number[]?, target: number[]?, follow: Module?, fov: number?}
function world.camera(c) end
---Message channel model for every connection: loss probability, extra steps in flight, messages per step per dock (the rest wait), payload limit (default 64 KiB); seeded from the world seed.
---@param c {loss: number?, delay: integer?, rate: integer?, max_bytes: integer?}
function world.channel(c) end
---The connection graph now, as `"json"` (modules, connections, components) or Graphviz `"dot"` text.
---@param format? "json"|"dot"
---@return string
function world.graph(format) end
---A module type's data as a table (loading it if needed): `{name=, file=, root=, mass=, links = {{name=, mass=, com=}}, joints = {{name=, parent=, child=, pivot=, axis=, lower=, upper=, continuous=, torque=, speed=, gain=, stiffness=}}, docks = {{name=, link=, at=, normal=, up=, quat=, gender=, size=, symmetry=, strength=, strength_torque=}}}`, poses in the module frame at zero joint angles (every link's frame); a dock's `quat` turns its link frame into the dock frame (x the outward normal, z its `up`). For models built from the types (`lua/kinematics.lua`).
---@param name string
---@return ModuleTypeData
function world.module_type(name) end
---Dock events so far (or since a time): `{time=, event=, module_a=, dock_a=, module_b=, dock_b=, force=, torque=, distance=, angle=}`; `event` is "engaged", "disengaged", "broken", "captured" (a capture joint began drawing the two docks together) or "stalled" (a capture not latched after the docks' `capture_time`); loads (N, N m) on "broken" ones, what is left to close (m, rad) on "stalled" ones.
---@param since? number
---@return {time: number, event: string, module_a: integer, dock_a: string, module_b: integer, dock_b: string, force: number?, torque: number?}[]
function world.events(since) end
---`{sent=, received=, dropped=}` counts so far (dropped: lost by the channel, sent on a free dock, or in flight over a connection that went).
---@return {sent: integer, received: integer, dropped: integer}
function world.messages() end
---`fn(t)` runs after every step.
---@param fn fun(t: number)
function world.on_step(fn) end
---Runs once when the run ends, however it ends: its `duration`, `world.stop()`, `--seconds`/`--steps`, Ctrl-C or SIGTERM (not after a world-script error); `t` is the end time. The place for checks that must run whatever the run's length.
---@param fn fun(t: number)
function world.on_end(fn) end
---`fn(t)` runs once after the step that reaches time `t`; a hook the run ends before is reported as a warning (a failure under `rm3d test`): checks that must run whatever the run's length go in `world.on_end`.
---@param t number
---@param fn fun(t: number)
function world.at(t, fn) end
---`fn(t)` runs every `period` seconds of simulated time (a period shorter than `dt` runs once per step); reported like `world.at` when it never ran.
---@param period number
---@param fn fun(t: number)
function world.every(period, fn) end
---Ends the run after this step.
function world.stop() end
---The simulated time (s).
---@return number
function world.time() end
---The control step (s).
---@return number
function world.dt() end
---Records a number in the series `name` (column `trace.<name>` of the world's rows in `--trace`); names are 1 to 64 letters, digits, `_`, `.`, `-`; the value a finite number; at most 256 names.
---@param name string
---@param value number
function world.trace(name, value) end
---A named result (same rules for name and value), under `"metrics"` in the `--json` summary; a later call with the same name replaces the value; typically set in `world.on_end`.
---@param name string
---@param value number a finite number
function world.metric(name, value) end
---For the Python API (docs/python.md): `fn(t)` runs when the agents' arrays are refreshed (after each step under `policy=True`) and returns a number (every module gets it) or a list with one number per module, in module order: the `reward` array. A wrong return is a world-script error naming what came back.
---@param fn fun(t: number): number|number[]
function world.reward(fn) end
---For the Python API: like `world.reward`, `fn(t)` returns a boolean (every module) or a list of booleans, one per module: the `done` array.
---@param fn fun(t: number): boolean|boolean[]
function world.done(fn) end
---A test assertion: a failure is recorded with file:line and the run goes on.
---@param cond any
---@param message? string
---@return boolean whether cond held
function expect(cond, message) end
---`--param key=value` pairs (numbers and true/false typed).
---@type table<string, string|number|boolean>
args = {}
---A line on stderr tagged with the time (`[   1.000 world] ...`); `print` is the same. `run --quiet` keeps these lines (it hides the modules' log lines).
---@param ... any
function log(...) end

---A module in the world (world side).
---@class Module
---@field id integer 1, 2, ... in spawn order
---@field name string
---@field type string module type name
local Module = {}
---The root link's position (m), also readable as `.x .y .z`.
---@return Vec3
function Module:position() end
---The root link's orientation.
---@return Quat
function Module:orientation() end
---The root link's linear velocity (m/s).
---@return Vec3 linear velocity, m/s
function Module:velocity() end
---A link's position in the world.
---@param link string
---@return Vec3
function Module:link_position(link) end
---A link's frame in the world: position and orientation.
---@param link string
---@return Vec3
---@return Quat
function Module:link_pose(link) end
---A joint's angle (rad).
---@param joint string
---@return number radians
function Module:joint_angle(joint) end
---Every joint's angle, by name.
---@return table<string, number>
function Module:joint_angles() end
---Torque (N m) its motor applied over the last step, and whether it was saturated.
---@param joint string
---@return number torque
---@return boolean saturated
function Module:joint_torque(joint) end
---A dock's state, seen from either side of a connection.
---@param dock string
---@return {enabled: boolean, engaged: boolean, peer_module: integer?, peer_dock: string?}
function Module:dock_state(dock) end
---A dock face's centre in the world.
---@param dock string
---@return Vec3
function Module:dock_position(dock) end
---A dock face's outward normal in the world.
---@param dock string
---@return Vec3
function Module:dock_normal(dock) end
---A dock's gender.
---@param dock string
---@return "male"|"female"|"none"
function Module:dock_gender(dock) end
---Load through the connection at this dock over the last step, or nil.
---@param dock string
---@return {force: number, torque: number}?
function Module:dock_load(dock) end
---Enables or disables a dock (a supervisor, or fault injection); an error for a faulted module.
---@param dock string
---@param enabled boolean
function Module:set_dock(dock, enabled) end
---A force (N, at most 1e9) on the root link during the next step.
---@param force number[] {fx, fy, fz}
function Module:push(force) end
---The raw sensor reading (an oracle for checks).
---@param name string
---@param field? "velocity"
---@return any
function Module:sensor(name, field) end
---`{joint=}`: the joint stalls where it is; `{dock=}`: the dock stops latching; `{sensor=}`: the sensor reads nil from now on. At any time (`world.at`).
---@param fault {joint: string?, dock: string?, sensor: string?}
function Module:inject_fault(fault) end
---The module's fault (file:line and traceback), or nil.
---@return string? fault text, nil when healthy
function Module:error() end
---A copy of what the module's behaviour last published under key (module.publish), or nil;
---without a key, a table of every key and value.
---@param key? string
---@return any
function Module:published(key) end

---An obstacle (world.box, sphere, cylinder, capsule, mesh).
---@class Body
local Body = {}
---The body's position.
---@return Vec3
function Body:position() end
---The body's orientation.
---@return Quat
function Body:orientation() end
---The body's linear velocity (m/s).
---@return Vec3
function Body:velocity() end
---True when the body is static or asleep (a dynamic obstacle still for 2 s; it wakes when touched).
---@return boolean
function Body:sleeping() end

---Terrain made by world.heightfield.
---@class Heightfield
local Heightfield = {}
---The surface's z over the world point (x, y), on the triangles bodies collide with; nil off the terrain.
---@param x number
---@param y number
---@return number?
function Heightfield:height_at(x, y) end
---The centre of the terrain in x and y; its base (black) in z.
---@return Vec3
function Heightfield:position() end
---Always upright: terrain is axis-aligned.
---@return Quat
function Heightfield:orientation() end
---Always zero: terrain is static.
---@return Vec3
function Heightfield:velocity() end
---The number of height samples (the image's pixels).
---@return integer
function Heightfield:count() end
---Samples along x and y (the image's width and height).
---@return integer nx
---@return integer ny
function Heightfield:resolution() end
---The box the terrain can fill (its base to base + height).
---@return {min: Vec3, max: Vec3}
function Heightfield:bounds() end

---A cloth (world.cloth): nodes on an nx x ny grid; node (ix, iy) from 0 is index iy * nx + ix + 1.
---@class Cloth
local Cloth = {}
---The number of nodes.
---@return integer nodes
function Cloth:count() end
---Nodes along corner 1→2 and 1→4.
---@return integer nx
---@return integer ny
function Cloth:resolution() end
---The box holding every node, or nil when a node is NaN.
---@return {min: Vec3, max: Vec3}? bounds of the nodes, nil when a node is NaN
function Cloth:bounds() end
---The mean node velocity.
---@return Vec3 mean node velocity
function Cloth:velocity() end
---Node i's position; node (ix, iy), counted from 0 along corner 1→2 and 1→4, is `iy * nx + ix + 1`.
---@param i integer node index, 1..count
---@return Vec3
function Cloth:node(i) end
---Every node's position, node 1 first.
---@return Vec3[] every node, node 1 first
function Cloth:positions() end
---Node i stays where it is now.
---@param i integer
function Cloth:pin(i) end
---Node i moves freely again.
---@param i integer
function Cloth:unpin(i) end
---Whether node i is pinned.
---@param i integer
---@return boolean
function Cloth:pinned(i) end

---Fluid or debris particles (world.fluid, world.debris).
---@class Particles
local Particles = {}
---The number of particles (it never changes).
---@return integer count particles in the system (never changes)
function Particles:count() end
---`"fluid"` or `"debris"`.
---@return "fluid"|"debris"
function Particles:kind() end
---Each particle's radius (m, half the spacing).
---@return number radius of each particle (m, half the spacing)
function Particles:radius() end
---The box holding every particle.
---@return Vec3 min
---@return Vec3 max
function Particles:bounds() end
---The mean velocity (m/s).
---@return Vec3 mean velocity (m/s)
function Particles:mean_velocity() end
---Every particle's position, in no fixed order (particles are re-sorted every step).
---@return Vec3[] positions one {x, y, z} per particle, in no fixed order
function Particles:positions() end
---How many particles are inside the box.
---@param min number[] {x, y, z}
---@param max number[] {x, y, z}
---@return integer count particles inside the box
function Particles:count_in(min, max) end
