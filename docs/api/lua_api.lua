-- The Lua API, written once. docs/api/generate.lua makes lua/meta/*.lua, docs/api/lua.md and
-- tests/api/api_types.lua from it; ctest api_generated fails when they are stale and
-- api_types runs tests/api/types_world.lua, which calls every function and checks the types.

file{"world", meta = "---@meta",
  header = [[-- LuaLS definitions of the world-script API (worlds/*.lua, tests/worlds/*.lua). Generated from
-- docs/api/lua_api.lua by docs/api/generate.lua: edit that file, not this one. ctest luals_meta
-- fails when a bound name is missing, api_generated when this file is stale, api_types when a
-- binding returns other types than declared. Reference page: docs/api/lua.md.]]}
alias{"Vec3", "{x: number, y: number, z: number, [1]: number, [2]: number, [3]: number}"}
alias{"Quat", "{w: number, x: number, y: number, z: number}"}

section{"World scripts", md = [[A world script runs once in its own VM to build the world and may keep hooks that run after every step. Its globals: `world`, `expect`, `args`, `log`/`print`, `require` (the script's folder, `lua/`, `behaviors/`). Positions are metres, angles radians, orientations quaternions `{w, x, y, z}`; a position may be given as `{x, y, z}`.]]}

class{"ShapeOptions",
  fields = {{"at?", "number[]", "{x, y, z}"},
            {"rot?", "number[]", "{roll, pitch, yaw}"},
            {"mass?", "number", "0 (default): static"},
            {"friction?", "number"},
            {"rolling_friction?", "number", "m: rolling and spinning resistance (default 0.0005 for dynamic bodies)"},
            {"velocity?", "number[]"}}}

class{"DockSettings",
  fields = {{"capture?", [["joint"|"magnet"]], "how a captured dock is drawn in (default joint)"},
            {"capture_radius?", "number", "m (0.03)"},
            {"capture_angle?", "number", "rad (0.5236, 30 deg)"},
            {"latch_distance?", "number", "m (0.004)"},
            {"latch_angle?", "number", "rad (0.0873, 5 deg)"},
            {"capture_speed?", "number", "m/s: the capture joint closes the faces at most this fast (0.05)"},
            {"capture_turn_speed?", "number", "rad/s: ... and turns them at most this fast (1)"},
            {"capture_force?", "number", "N: the most force the capture joint exerts (20)"},
            {"capture_torque?", "number", "N m: the most torque it exerts (1)"},
            {"capture_time?", "number", "s: a capture not latched after this is reported stalled (3)"},
            {"pull?", "number", "N: the magnet's pull (2)"},
            {"strength?", "number", "N: a connection breaks above this force (100)"},
            {"strength_torque?", "number", "N m: ... or above this torque (10)"}}}

class{"world",
  table = "world = {}"}
fn{"world.set", doc = [[Settings, all optional (seed before the first spawn); `solver` is `"exact"` (default: 1 substep x 15 iterations, 2 x 15 in a world with cloth) or `"pgs"` (default: 4 x 30; substeps and iterations given are kept; see [Physics](../physics.md)); `max_speed`, `max_angular_speed` and `bounds` are the divergence limits; `expect_faults = true` (or a number: exactly that many faulted modules) declares that the world faults modules on purpose, which `rm3d test` otherwise fails.]],
  params = {{"s", [[{dt: number?, substeps: integer?, gravity: number[]?, seed: integer?, duration: number?, solver: ("pgs"|"exact")?, solver_iterations: integer?, joint_iterations: integer?, erp: number?, max_speed: number?, max_angular_speed: number?, bounds: number?, expect_faults: (boolean|integer)?}]]}}}
fn{"world.ground", doc = "Infinite plane z = 0.",
  params = {{"g?", "{friction: number?, restitution: number?}"}}}
fn{"world.box", doc = "Obstacle; mass 0 (default) is static; a dynamic one may start moving, sleeps once still and wakes when touched; `rolling_friction` (m, default 0.0005 for dynamic bodies) resists rolling and spinning; returns a Body.",
  params = {{"o", "ShapeOptions|{size: number[]}"}},
  returns = {{"Body"}}}
fn{"world.sphere", doc = "An obstacle sphere; the other options as `world.box`.",
  params = {{"o", "ShapeOptions|{radius: number}"}},
  returns = {{"Body"}}}
fn{"world.cylinder", doc = "An obstacle cylinder along its local z; the other options as `world.box`.",
  params = {{"o", "ShapeOptions|{radius: number, length: number}"}},
  returns = {{"Body"}}}
fn{"world.capsule", doc = "A cylinder of `length` along its local z capped by hemispheres: `length + 2 radius` overall.",
  params = {{"o", "ShapeOptions|{radius: number, length: number}"}},
  returns = {{"Body"}}}
fn{"world.mesh", doc = "The convex hull of a mesh file (OBJ, STL, ... through assimp); `concave = true`: the mesh's own triangles, static only (level geometry).",
  params = {{"o", "ShapeOptions|{file: string, scale: number?, concave: boolean?}"}},
  returns = {{"Body"}}}
fn{"world.cloth", doc = "A cloth (see [Cloth](../environments.md#cloth)): corners in order around the edge; `resolution` nodes along corner 1→2 and 1→4 (2..256 each, at most 65,536; default 16 x 16); `mass` kg of the whole sheet (default 0.1); `stiffness` in (0, 1] (default 0.9); `pinned` corners (1..4) and `pinned_nodes` (1..nx·ny) held fixed in space; `friction` in [0, 1] (default 0.5, times the body's); `thickness` 0.0001..0.1 m (default 0.005); returns a Cloth.",
  params = {{"o", "{corners: number[][], resolution: integer[]?, mass: number?, stiffness: number?, pinned: integer[]?, pinned_nodes: integer[]?, friction: number?, thickness: number?, color: number[]?}"}},
  returns = {{"Cloth"}}}
fn{"world.heightfield", doc = "Static terrain from a grayscale image (see [Environments](../environments.md)): one sample per pixel, black at `at.z`, white at `at.z + height`, centred on (`at.x`, `at.y`), `size` the extent from the first sample to the last; `image`, `size` and `height` required; returns a Heightfield.",
  params = {{"o", "{image: string, size: number[], height: number, at: number[]?, friction: number?}"}},
  returns = {{"Heightfield"}}}
fn{"world.fluid", doc = [[Fills the box with fluid particles on a lattice `spacing` apart (default 0.02 m; the particle radius is half of it; `density` 1000 kg/m³, XSPH `viscosity` 0.01, s_corr `tension` 0.01, `iterations` 3 a step, split over `substeps` (default one per iteration, at most `iterations`), `kernel` radius 1.8 spacings); returns a Particles handle (see [Fluids and debris](../environments.md#fluids-and-debris)); position-based fluids (Macklin and Mueller 2013), coupled both ways with bodies and modules.]],
  params = {{"o", "{min: number[], max: number[], spacing: number?, density: number?, viscosity: number?, tension: number?, friction: number?, kinetic_friction: number?, damping: number?, iterations: integer?, substeps: integer?, kernel: number?, max_speed: number?}"}},
  returns = {{"Particles"}}}
fn{"world.debris", doc = "The same with grains (`density` 1600, `friction` 0.6 static, kinetic 0.8 of it, `damping` 0.5 /s, `substeps` 1); at most 2,000,000 particles in a world.",
  params = {{"o", "{min: number[], max: number[], spacing: number?, density: number?, friction: number?, kinetic_friction: number?, damping: number?, iterations: integer?, substeps: integer?, max_speed: number?}"}},
  returns = {{"Particles"}}}
fn{"world.spawn", doc = "A module of `assets/modules/<type>.lua` (or of a module-type file given by path), its root link at `at` (metres) turned by `rot` (`{roll, pitch, yaw}` in radians, about the fixed x, then y, then z axes) or `quat` (`{w, x, y, z}`, normalised; it wins over `rot`); `fixed = true` holds its root link in place (a base); `joints` is its initial posture, angles in radians by joint name (`{pitch = 0.5}`) or in joint order (`{0.5, 0, -0.3}`), within the joints' limits: the root link is at `at` and the other links follow, and the servos hold that posture until commanded; returns a Module.",
  params = {{"type", "string", "a module type name or a module-type file"}, {"o?", "{at: number[]?, rot: number[]?, quat: number[]?, name: string?, behavior: string?, params: table?, fixed: boolean?, joints: table<string|integer, number>?, docks: DockSettings?}"}},
  returns = {{"Module"}}}
fn{"world.docks", doc = [[Dock settings over the module types' for every module spawned after the call (a key left out keeps the type's value; `world.spawn`'s `docks` does the same for one module, over these): `capture` `"joint"` (the default: a capture joint draws the faces together, see [Docking at run time](../physics.md#docking-at-run-time)) or `"magnet"` (a force `pull` at each face), and the dock keys of a module-type file: `capture_radius`, `capture_angle`, `latch_distance`, `latch_angle`, `capture_speed`, `capture_turn_speed`, `capture_force`, `capture_torque`, `capture_time`, `pull`, `strength`, `strength_torque`.]],
  params = {{"s", "DockSettings"}}}
fn{"world.place_facing", doc = [[Before the first step: places b (and what is docked to it) so its dock `dock_b` faces a's `dock_a` squarely, `gap` metres (default 0.01) out along a's normal, turned `orientation` x 360/symmetry degrees about it (default 0); nothing is locked (the docks latch at run time if they are within capture; for modules on the ground, then `world.place_on_ground(b)`).]],
  params = {{"a", "Module"}, {"dock_a", "string"}, {"b", "Module"}, {"dock_b", "string"}, {"gap?", "number", "metres between the faces (default 0.01)"}, {"orientation?", "integer", "turns about the normal (default 0)"}}}
fn{"world.place_on_ground", doc = "Before the first step: moves m and everything connected to it straight down (or up) until the lowest point of their collision shapes is at height `z` (default 0, the ground plane); returns how far it moved (m).",
  params = {{"m", "Module"}, {"z?", "number", "metres (default 0, the ground plane)"}},
  returns = {{"number", "moved metres moved (+ up)"}}}
fn{"world.connect", doc = "Places b (and what is docked to it) so the docks mate face to face, turned `orientation` x 90° about the normal, and locks them; if a and b are already connected another way the docks must already face each other (closing a loop).",
  params = {{"a", "Module"}, {"dock_a", "string"}, {"b", "Module"}, {"dock_b", "string"}, {"orientation?", "integer", "quarter turns about the normal"}}}
fn{"world.modules", doc = "Every module, in spawn order.",
  returns = {{"Module[]"}}}
fn{"world.module", doc = "The module with that id or name, or nil.",
  params = {{"id_or_name", "integer|string"}},
  returns = {{"Module?"}}}
fn{"world.components", doc = "The connected components (modules joined by engaged docks), as arrays of Modules.",
  returns = {{"Module[][]"}}}
fn{"world.camera", doc = "The picture's view; with `follow`, `eye` is an offset from that module.",
  params = {{"c", "{eye: number[]?, target: number[]?, follow: Module?, fov: number?}"}}}
fn{"world.channel", doc = "Message channel model for every connection: loss probability, extra steps in flight, messages per step per dock (the rest wait), payload limit (default 64 KiB); seeded from the world seed.",
  params = {{"c", "{loss: number?, delay: integer?, rate: integer?, max_bytes: integer?}"}}}
fn{"world.graph", doc = [[The connection graph now, as `"json"` (modules, connections, components) or Graphviz `"dot"` text.]],
  params = {{"format?", [["json"|"dot"]]}},
  returns = {{"string"}}}
fn{"world.module_type", doc = "A module type's data as a table (loading it if needed): `{name=, file=, root=, mass=, links = {{name=, mass=, com=}}, joints = {{name=, parent=, child=, pivot=, axis=, lower=, upper=, continuous=, torque=, speed=, gain=, stiffness=}}, docks = {{name=, link=, at=, normal=, up=, quat=, gender=, size=, symmetry=, strength=, strength_torque=}}}`, poses in the module frame at zero joint angles (every link's frame); a dock's `quat` turns its link frame into the dock frame (x the outward normal, z its `up`). For models built from the types (`lua/kinematics.lua`).",
  params = {{"name", "string"}},
  returns = {{"ModuleTypeData"}}}
fn{"world.events", doc = [[Dock events so far (or since a time): `{time=, event=, module_a=, dock_a=, module_b=, dock_b=, force=, torque=, distance=, angle=}`; `event` is "engaged", "disengaged", "broken", "captured" (a capture joint began drawing the two docks together) or "stalled" (a capture not latched after the docks' `capture_time`); loads (N, N m) on "broken" ones, what is left to close (m, rad) on "stalled" ones.]],
  params = {{"since?", "number"}},
  returns = {{"{time: number, event: string, module_a: integer, dock_a: string, module_b: integer, dock_b: string, force: number?, torque: number?}[]"}}}
fn{"world.messages", doc = "`{sent=, received=, dropped=}` counts so far (dropped: lost by the channel, sent on a free dock, or in flight over a connection that went).",
  returns = {{"{sent: integer, received: integer, dropped: integer}"}}}
fn{"world.on_step", doc = "`fn(t)` runs after every step.",
  params = {{"fn", "fun(t: number)"}}}
fn{"world.on_end", doc = "Runs once when the run ends, however it ends: its `duration`, `world.stop()`, `--seconds`/`--steps`, Ctrl-C or SIGTERM (not after a world-script error); `t` is the end time. The place for checks that must run whatever the run's length.",
  params = {{"fn", "fun(t: number)"}}}
fn{"world.at", doc = "`fn(t)` runs once after the step that reaches time `t`; a hook the run ends before is reported as a warning (a failure under `rm3d test`): checks that must run whatever the run's length go in `world.on_end`.",
  params = {{"t", "number"}, {"fn", "fun(t: number)"}}}
fn{"world.every", doc = "`fn(t)` runs every `period` seconds of simulated time (a period shorter than `dt` runs once per step); reported like `world.at` when it never ran.",
  params = {{"period", "number"}, {"fn", "fun(t: number)"}}}
fn{"world.stop", doc = "Ends the run after this step."}
fn{"world.time", doc = "The simulated time (s).",
  returns = {{"number"}}}
fn{"world.dt", doc = "The control step (s).",
  returns = {{"number"}}}
fn{"world.trace", doc = "Records a number in the series `name` (column `trace.<name>` of the world's rows in `--trace`); names are 1 to 64 letters, digits, `_`, `.`, `-`; the value a finite number; at most 256 names.",
  params = {{"name", "string"}, {"value", "number"}}}
fn{"world.metric", doc = [[A named result (same rules for name and value), under `"metrics"` in the `--json` summary; a later call with the same name replaces the value; typically set in `world.on_end`.]],
  params = {{"name", "string"}, {"value", "number", "a finite number"}}}
fn{"world.reward", doc = [[For the Python API (docs/python.md): `fn(t)` runs when the agents' arrays are refreshed (after each step under `policy=True`) and returns a number (every module gets it) or a list with one number per module, in module order: the `reward` array. A wrong return is a world-script error naming what came back.]],
  params = {{"fn", "fun(t: number): number|number[]"}}}
fn{"world.done", doc = [[For the Python API: like `world.reward`, `fn(t)` returns a boolean (every module) or a list of booleans, one per module: the `done` array.]],
  params = {{"fn", "fun(t: number): boolean|boolean[]"}}}
fn{"expect", doc = "A test assertion: a failure is recorded with file:line and the run goes on.",
  params = {{"cond", "any"}, {"message?", "string"}},
  returns = {{"boolean", "whether cond held"}}}
global{"args", type = "table<string, string|number|boolean>", value = "{}",
  doc = "`--param key=value` pairs (numbers and true/false typed)."}
fn{"log", doc = "A line on stderr tagged with the time (`[   1.000 world] ...`); `print` is the same. `run --quiet` keeps these lines (it hides the modules' log lines).",
  params = {{"...", "any"}}}

section{"Handles in world scripts", md = [[What `world.spawn`, `world.box` and the others return. A Module handle (world side) reads anything about its module; its writes (`set_dock`, `push`, `inject_fault`) act as a supervisor or a fault injector would.]]}

class{"Module",
  doc = "A module in the world (world side).",
  fields = {{"id", "integer", "1, 2, ... in spawn order"},
            {"name", "string"},
            {"type", "string", "module type name"}},
  table = "local Module = {}"}
fn{"Module:position", doc = "The root link's position (m), also readable as `.x .y .z`.",
  returns = {{"Vec3"}}}
fn{"Module:orientation", doc = "The root link's orientation.",
  returns = {{"Quat"}}}
fn{"Module:velocity", doc = "The root link's linear velocity (m/s).",
  returns = {{"Vec3", "linear velocity, m/s"}}}
fn{"Module:link_position", doc = "A link's position in the world.",
  params = {{"link", "string"}},
  returns = {{"Vec3"}}}
fn{"Module:link_pose", doc = "A link's frame in the world: position and orientation.",
  params = {{"link", "string"}},
  returns = {{"Vec3"}, {"Quat"}}}
fn{"Module:joint_angle", doc = "A joint's angle (rad).",
  params = {{"joint", "string"}},
  returns = {{"number", "radians"}}}
fn{"Module:joint_angles", doc = "Every joint's angle, by name.",
  returns = {{"table<string, number>"}}}
fn{"Module:joint_torque", doc = "Torque (N m) its motor applied over the last step, and whether it was saturated.",
  params = {{"joint", "string"}},
  returns = {{"number", "torque"}, {"boolean", "saturated"}}}
fn{"Module:dock_state", doc = "A dock's state, seen from either side of a connection.",
  params = {{"dock", "string"}},
  returns = {{"{enabled: boolean, engaged: boolean, peer_module: integer?, peer_dock: string?}"}}}
fn{"Module:dock_position", doc = "A dock face's centre in the world.",
  params = {{"dock", "string"}},
  returns = {{"Vec3"}}}
fn{"Module:dock_normal", doc = "A dock face's outward normal in the world.",
  params = {{"dock", "string"}},
  returns = {{"Vec3"}}}
fn{"Module:dock_gender", doc = "A dock's gender.",
  params = {{"dock", "string"}},
  returns = {{[["male"|"female"|"none"]]}}}
fn{"Module:dock_load", doc = "Load through the connection at this dock over the last step, or nil.",
  params = {{"dock", "string"}},
  returns = {{"{force: number, torque: number}?"}}}
fn{"Module:set_dock", doc = "Enables or disables a dock (a supervisor, or fault injection); an error for a faulted module.",
  params = {{"dock", "string"}, {"enabled", "boolean"}}}
fn{"Module:push", doc = "A force (N, at most 1e9) on the root link during the next step.",
  params = {{"force", "number[]", "{fx, fy, fz}"}}}
fn{"Module:sensor", doc = "The raw sensor reading (an oracle for checks).",
  params = {{"name", "string"}, {"field?", [["velocity"]]}},
  returns = {{"any"}}}
fn{"Module:inject_fault", doc = "`{joint=}`: the joint stalls where it is; `{dock=}`: the dock stops latching; `{sensor=}`: the sensor reads nil from now on. At any time (`world.at`).",
  params = {{"fault", "{joint: string?, dock: string?, sensor: string?}"}}}
fn{"Module:error", doc = "The module's fault (file:line and traceback), or nil.",
  returns = {{"string?", "fault text, nil when healthy"}}}
fn{"Module:published", doc = [[A copy of what the module's behaviour last published under key (module.publish), or nil;
without a key, a table of every key and value.]],
  params = {{"key?", "string"}},
  returns = {{"any"}}}

class{"Body",
  doc = "An obstacle (world.box, sphere, cylinder, capsule, mesh).",
  table = "local Body = {}"}
fn{"Body:position", doc = "The body's position.",
  returns = {{"Vec3"}}}
fn{"Body:orientation", doc = "The body's orientation.",
  returns = {{"Quat"}}}
fn{"Body:velocity", doc = "The body's linear velocity (m/s).",
  returns = {{"Vec3"}}}
fn{"Body:sleeping", doc = "True when the body is static or asleep (a dynamic obstacle still for 2 s; it wakes when touched).",
  returns = {{"boolean"}}}

class{"Heightfield",
  doc = "Terrain made by world.heightfield.",
  table = "local Heightfield = {}"}
fn{"Heightfield:height_at", doc = "The surface's z over the world point (x, y), on the triangles bodies collide with; nil off the terrain.",
  params = {{"x", "number"}, {"y", "number"}},
  returns = {{"number?"}}}
fn{"Heightfield:position", doc = "The centre of the terrain in x and y; its base (black) in z.",
  returns = {{"Vec3"}}}
fn{"Heightfield:orientation", doc = "Always upright: terrain is axis-aligned.",
  returns = {{"Quat"}}}
fn{"Heightfield:velocity", doc = "Always zero: terrain is static.",
  returns = {{"Vec3"}}}
fn{"Heightfield:count", doc = "The number of height samples (the image's pixels).",
  returns = {{"integer"}}}
fn{"Heightfield:resolution", doc = "Samples along x and y (the image's width and height).",
  returns = {{"integer", "nx"}, {"integer", "ny"}}}
fn{"Heightfield:bounds", doc = "The box the terrain can fill (its base to base + height).",
  returns = {{"{min: Vec3, max: Vec3}"}}}

class{"Cloth",
  doc = "A cloth (world.cloth): nodes on an nx x ny grid; node (ix, iy) from 0 is index iy * nx + ix + 1.",
  table = "local Cloth = {}"}
fn{"Cloth:count", doc = "The number of nodes.",
  returns = {{"integer", "nodes"}}}
fn{"Cloth:resolution", doc = "Nodes along corner 1→2 and 1→4.",
  returns = {{"integer", "nx"}, {"integer", "ny"}}}
fn{"Cloth:bounds", doc = "The box holding every node, or nil when a node is NaN.",
  returns = {{"{min: Vec3, max: Vec3}?", "bounds of the nodes, nil when a node is NaN"}}}
fn{"Cloth:velocity", doc = "The mean node velocity.",
  returns = {{"Vec3", "mean node velocity"}}}
fn{"Cloth:node", doc = "Node i's position; node (ix, iy), counted from 0 along corner 1→2 and 1→4, is `iy * nx + ix + 1`.",
  params = {{"i", "integer", "node index, 1..count"}},
  returns = {{"Vec3"}}}
fn{"Cloth:positions", doc = "Every node's position, node 1 first.",
  returns = {{"Vec3[]", "every node, node 1 first"}}}
fn{"Cloth:pin", doc = "Node i stays where it is now.",
  params = {{"i", "integer"}}}
fn{"Cloth:unpin", doc = "Node i moves freely again.",
  params = {{"i", "integer"}}}
fn{"Cloth:pinned", doc = "Whether node i is pinned.",
  params = {{"i", "integer"}},
  returns = {{"boolean"}}}

class{"Particles",
  doc = "Fluid or debris particles (world.fluid, world.debris).",
  table = "local Particles = {}"}
fn{"Particles:count", doc = "The number of particles (it never changes).",
  returns = {{"integer", "count particles in the system (never changes)"}}}
fn{"Particles:kind", doc = [[`"fluid"` or `"debris"`.]],
  returns = {{[["fluid"|"debris"]]}}}
fn{"Particles:radius", doc = "Each particle's radius (m, half the spacing).",
  returns = {{"number", "radius of each particle (m, half the spacing)"}}}
fn{"Particles:bounds", doc = "The box holding every particle.",
  returns = {{"Vec3", "min"}, {"Vec3", "max"}}}
fn{"Particles:mean_velocity", doc = "The mean velocity (m/s).",
  returns = {{"Vec3", "mean velocity (m/s)"}}}
fn{"Particles:positions", doc = "Every particle's position, in no fixed order (particles are re-sorted every step).",
  returns = {{"Vec3[]", "positions one {x, y, z} per particle, in no fixed order"}}}
fn{"Particles:count_in", doc = "How many particles are inside the box.",
  params = {{"min", "number[]", "{x, y, z}"}, {"max", "number[]", "{x, y, z}"}},
  returns = {{"integer", "count particles inside the box"}}}

file{"behaviour", meta = "---@meta",
  header = [[-- LuaLS definitions of the behaviour API (behaviors/*.lua): the globals a module's VM gets.
-- Generated from docs/api/lua_api.lua by docs/api/generate.lua: edit that file, not this one.
-- Reference page: docs/api/lua.md.]]}

section{"Behaviours", md = [[Globals: `module`, `params` (a copy of the spawn params), `state` (a table for your own state),
`sim`, `log`/`print`. Callbacks the script may define: `init()` (once, before the first step),
`step(dt)`, `on_dock(dock, event)`, `on_reload()`.]]}

class{"Joint",
  doc = "A joint of the module (module.joint(name)).",
  table = "local Joint = {}"}
fn{"Joint:angle", doc = "The joint's angle now, radians: the child link's rotation relative to its parent, right-handed about the joint axis.",
  returns = {{"number", "radians, child relative to parent"}}}
fn{"Joint:velocity", doc = "The joint's angular speed now, rad/s, with the sign of `angle`.",
  returns = {{"number", "rad/s"}}}
fn{"Joint:torque", doc = "The torque the motor (with the limit stop, when in contact) applied over the last step, N·m, and whether that was its full rating (it could not hold or reach its command).",
  returns = {{"number", "torque"}, {"boolean", "saturated"}}}
fn{"Joint:saturated", doc = "True when the motor gave its full rating over the last step (it could not hold or reach its command); `torque` gives the torque too.",
  returns = {{"boolean"}}}
fn{"Joint:set_target", doc = "Position servo within limits, torque and speed.",
  params = {{"rad", "number"}}}
fn{"Joint:set_velocity", doc = "Velocity drive within torque and speed.",
  params = {{"rad_s", "number"}}}
fn{"Joint:free", doc = "Motor off."}
fn{"Joint:target", doc = "Last servo target or nil.",
  returns = {{"number?", "last servo target"}}}
fn{"Joint:limits", doc = "Lower, upper.",
  returns = {{"number", "lower"}, {"number", "upper"}}}
fn{"Joint:name", doc = "Name.",
  returns = {{"string"}}}

class{"Dock",
  doc = "A dock of the module (module.dock(name)).",
  table = "local Dock = {}"}
fn{"Dock:enabled", doc = "True when the dock is willing to connect (`enable`/`disable`).",
  returns = {{"boolean"}}}
fn{"Dock:engaged", doc = "True while the dock is latched to another.",
  returns = {{"boolean"}}}
fn{"Dock:gender", doc = "The dock's gender in the module type: `\"male\"` latches only to `\"female\"` and the reverse; `\"none\"` (genderless, as SuperBot's) only to `\"none\"`.",
  returns = {{[["male"|"female"|"none"]]}}}
fn{"Dock:enable", doc = "Makes the dock willing to connect: it latches to a facing willing dock within the capture limits."}
fn{"Dock:disable", doc = "Makes the dock unwilling to connect; an engaged dock lets go (an undock)."}
fn{"Dock:send", doc = "Queue a plain value (nil, boolean, number, string, tables of these; at most 64 KiB) for the module docked here, readable next step; false when nothing is engaged, or when this step's sends already fill 8 MiB (counted as dropped).",
  params = {{"value", "any", "nil, boolean, number, string, tables of these"}},
  returns = {{"boolean", "sent false when nothing is engaged"}}}
fn{"Dock:name", doc = "The dock's name in the module type.",
  returns = {{"string"}}}
fn{"Dock:peer", doc = "While engaged, the module id and dock name it is latched to; nil otherwise.",
  returns = {{"integer?", "peer module id"}, {"string?", "peer dock name"}}}

class{"module",
  fields = {{"id", "integer"},
            {"name", "string"},
            {"type", "string"}},
  table = "module = {}"}
fn{"module.joint", doc = "The joint of this name (an error naming the type's joints when there is none).",
  params = {{"name", "string"}},
  returns = {{"Joint"}}}
fn{"module.joints", doc = "The names of the module type's joints, in joint order.",
  returns = {{"string[]"}}}
fn{"module.type_data", doc = "This module's type as data (the table `world.module_type` gives), or that of another type a module of this world was spawned with.",
  params = {{"name?", "string"}},
  returns = {{"ModuleTypeData"}}}
fn{"module.dock", doc = "The dock of this name (an error naming the type's docks when there is none).",
  params = {{"name", "string"}},
  returns = {{"Dock"}}}
fn{"module.docks", doc = "The names of the module type's docks, in dock order.",
  returns = {{"string[]"}}}
fn{"module.receive", doc = "The oldest pending message (on that dock), consumed.",
  params = {{"dock?", "string"}},
  returns = {{"{dock: string, data: any, time: number}?"}}}
fn{"module.sensor", doc = "A raw sensor reading this step (see Sensors).",
  params = {{"name", "string"}, {"field?", [["velocity"]]}},
  returns = {{"any"}}}
fn{"module.has_sensor", doc = "Whether the type has that sensor (and, if not, what it has).",
  params = {{"name", "string"}},
  returns = {{"boolean"}, {"string?", "the sensors it has, when not"}}}
fn{"module.sense", doc = "A declared percept's value this step.",
  params = {{"name", "string"}},
  returns = {{"any"}}}
fn{"module.act", doc = "A command through a declared action (see Percepts).",
  params = {{"name", "string"}, {"value", "any"}}}
fn{"module.trace", doc = "Records a number in the series `name` (column `trace.<name>` of this module's rows in `--trace`, and the viewer's plots); names are 1 to 64 letters, digits, `_`, `.`, `-`; the value a finite number; at most 256 names per behaviour.",
  params = {{"name", "string"}, {"value", "number"}}}
fn{"module.publish", doc = "Makes a plain value (as a message payload, at most 64 KiB) readable by the world script as `m:published(key)` until it is published again (nil removes the key): how a world checks what a module has computed, such as a map learned from messages (`worlds/discovery.lua`); keys as trace names, at most 256 per module; the world reads it after the step.", doc = [[Makes a plain value (at most 64 KiB) readable by the world script as m:published(key), until
published again; nil removes the key. Keys: 1 to 64 letters, digits, _ . -; at most 256.]],
  params = {{"key", "string"}, {"value", "any"}}}

class{"RandomStream",
  fields = {{"random", "fun(m?: integer, n?: integer): number"},
            {"gaussian", "fun(mu?: number, sigma?: number): number"}}}

class{"sim",
  table = "sim = {}"}
fn{"sim.time", doc = "Simulated seconds since the start.",
  returns = {{"number", "seconds since the start"}}}
fn{"sim.dt", doc = "The control step, seconds (the world's `dt`).",
  returns = {{"number", "the control step"}}}
fn{"sim.random", doc = "A number from the module's own random stream, as `math.random` (`math.random` and `math.randomseed` use the stream too): [0, 1), or a whole number in [1, m] or [m, n].",
  params = {{"m?", "integer"}, {"n?", "integer"}},
  returns = {{"number"}}}
fn{"sim.gaussian", doc = "A normal deviate from the module's own random stream, mean `mu` (default 0) and standard deviation `sigma` (default 1).",
  params = {{"mu?", "number"}, {"sigma?", "number"}},
  returns = {{"number"}}}
fn{"sim.stream", doc = "A random stream of its own, seeded from the world seed, the module's stream and `key`: draws elsewhere never shift it (`stream.random()`, `stream.gaussian(mu, sigma)`, called with a dot).",
  params = {{"key", "string"}},
  returns = {{"RandomStream"}}}
global{"params", type = "table<string, any>", value = "{}",
  doc = "A copy of the spawn params."}
global{"state", type = "table", value = "{}",
  doc = "A table for your own state; survives hot reload."}
lua{[[noise = require("noise")]], doc = "Noise models (lua/noise.lua)."}

class{"PerceptSpec",
  fields = {{"sensor", "string"},
            {"field?", [["velocity"]]},
            {"noise?", "table", "a noise model or a list of them"},
            {"map?", "fun(v: any): any"}}}
global{"percepts", type = "table<string, PerceptSpec>", value = "{}"}

class{"ActionSpec",
  fields = {{"joint?", "string"},
            {"dock?", "string"},
            {"mode?", [["target"|"velocity"]]},
            {"noise?", "table"},
            {"map?", "fun(v: any): any"}}}
global{"actions", type = "table<string, ActionSpec>", value = "{}"}
fn{"init", doc = "Callbacks a behaviour may define."}
fn{"step", doc = "Called every control step (after `on_dock` events).",
  params = {{"dt", "number"}}}
fn{"observe", doc = [[For the Python API (docs/python.md): the module's row of the `obs` array, a list of finite numbers (at most 4096). Without it the row is the joint angles (rad), the joint velocities (rad/s), then per dock 1 if engaged else 0. An error or a bad return faults the module.]],
  returns = {{"number[]"}}}
fn{"act", doc = [[For the Python API: called each step under `policy=True`, before `step(dt)`, with the module's row of the `act` array (`act_size` numbers; by default one per joint). Without it the row sets the joints' servo targets (rad). Whatever it sends through a dock arrives next step, as from `step`.]],
  params = {{"a", "number[]"}}}
global{"act_size", type = "integer", value = "nil",
  doc = "How many numbers `act(a)` takes, a whole number from 0 to 4096 (1.5 faults the module; it is never rounded); unset: the module's joint count."}
fn{"on_reload", doc = "Called after a hot reload replaced the behaviour's definitions (`state` survives)."}
fn{"on_dock", doc = [[Called at the start of the module's next step for each dock event: `dock` is the Dock handle (compare `dock:name() == "front"`), `event` what happened: "engaged", "disengaged" or "broken"; and, before a connection exists, "captured" (a capture joint has begun drawing this dock and another together) and "stalled" (that capture has not latched after `capture_time`).]],
  params = {{"dock", "Dock"}, {"event", [["engaged"|"disengaged"|"broken"|"captured"|"stalled"]]}}}

text[[Behaviour VMs are sandboxed: `base` (without `dofile`, `loadfile`; `load` takes text only),
`table`, `string`, `math`, `utf8`, `coroutine`, and `require` limited to the script's folder,
`lua/` and `behaviors/`. Each VM has a memory cap (32 MiB) and an instruction budget per call
(10 million); a behaviour that errors, loops forever or eats memory **faults only its own
module** (its joints keep their last commands), reported with file:line and a traceback.
Limits hold inside everything a script can reach: the budget is shared by a VM's coroutines and
cannot be caught by `pcall` (once spent, every further instruction raises until the call returns);
`string.find(`, `string.match(`, `string.gmatch(` and `string.gsub(` are our own Lua 5.4-compatible
matcher whose backtracking is charged to the budget; `string.rep` checks its result against the
memory cap first. The memory cap is soft: crossing it raises "out of memory: ..." at the next
instruction, with file:line and a traceback (allocations fail outright only past 1.25x). The world
VM has a cap too (256 MiB). A wall-clock watchdog (`RunOptions::watchdogSeconds`, default 5 s)
interrupts a call that does not return in time ("watchdog: step() did not return within 5 s");
if it still does not return, the process ends with exit code 3. `setmetatable` refuses metatables
with `__gc` (Lua runs finalizers with hooks off, out of reach of every limit). Unread messages
count against a per-module limit (8 MiB): further ones are dropped, said once in the module's log.
`require` takes dot-separated names only (`lib.noise`) and refuses files that resolve (through
symlinks) outside its folders.

Shared Lua library (`lua/`): `gaits` (`gaits.wave`, `gaits.square`), `vec` (vectors and
quaternions for world scripts and module types), `atron` (ATRON lattice helpers),
`rolling_gait` (the rolling track's gait, for behaviours that build on it),
`rolling_track_world` (builds and checks a rolling track in a world), `kinematics`
(below), `elongated_dock_type` (elongated docks of any length), `arm_ik_world` (the arm of
`worlds/arm_ik.lua`), `arm_control` (what the arm controllers share: the limit-aware damped
least-squares step, its adaptive damping, the integrated servo command), `snake_chain`
(`snake_chain.build{n=, amplitude=, lag=, behavior=, pose = "gait"|"flat"}`: a chain of modules
docked back to front, either straight or already in its travelling wave's pose at t = 0, turned
with `kinematics` so that it rests on its troughs and put down with `world.place_on_ground`, so a
long chain never has to shorten against friction to start its wave, and no end is left to fall).]]

file{"linalg", meta = "---@meta linalg",
  header = [[-- LuaLS definitions of `require("linalg")` (vectors, matrices, quaternions, rigid transforms;
-- docs/api/lua.md, "Linear algebra"; generated from docs/api/lua_api.lua) and of the module-type data tables (world.module_type,
-- module.type_data). Indices start at 1.]]}

section{"Module-type data", md = "What `world.module_type(name)` and `module.type_data([name])` return."}

class{"ModuleTypeData",
  doc = "A link, joint and dock description of a module type (poses in the module frame at zero angles).",
  fields = {{"name", "string"},
            {"file", "string"},
            {"root", "string"},
            {"mass", "number"},
            {"links", "{name: string, mass: number, com: number[]}[]"},
            {"joints", "{name: string, parent: string, child: string, pivot: number[], axis: number[], lower: number, upper: number, continuous: boolean, torque: number, speed: number, gain: number, stiffness: number}[]"},
            {"docks", "{name: string, link: string, at: number[], normal: number[], up: number[], quat: number[], gender: string, size: number, symmetry: integer, strength: number, strength_torque: number}[]"}}}

section{"Linear algebra", md = [[`local linalg = require("linalg")` in behaviours, world scripts and module-type files: vectors
and dense matrices of any size (doubles, built into the engine on Eigen), unit quaternions and
rigid transforms. Indices start at 1. Matrices and vectors are values: every operation returns a
new one, except `set`.]]}

class{"linalg.matrix",
  doc = [[A dense matrix or a vector (an n x 1 column made by linalg.vector). Operators: + - * / (by a
number), unary -, ==, # (entries of a vector, rows of a matrix).]],
  operators = {"add(linalg.matrix): linalg.matrix", "sub(linalg.matrix): linalg.matrix", "mul(linalg.matrix|number): linalg.matrix", "div(number): linalg.matrix", "unm: linalg.matrix", "len: integer"},
  table = "local Matrix = {}"}
fn{"Matrix:rows", doc = "The number of rows.",
  returns = {{"integer"}}}
fn{"Matrix:cols", doc = "The number of columns.",
  returns = {{"integer"}}}
fn{"Matrix:get", doc = "Entry (i, j), or entry i of a vector.",
  params = {{"i", "integer"}, {"j?", "integer"}},
  returns = {{"number"}}}
fn{"Matrix:set", doc = "Sets entry (i, j) to x (or entry i of a vector to j) and returns the matrix.",
  params = {{"i", "integer"}, {"j", "number"}, {"x?", "number"}},
  returns = {{"linalg.matrix"}}}
fn{"Matrix:t", doc = "Transpose (of a vector: a 1 x n matrix).",
  returns = {{"linalg.matrix"}}}
fn{"Matrix:inv", doc = "The inverse (an error when singular).",
  returns = {{"linalg.matrix"}}}
fn{"Matrix:det", doc = "The determinant of a square matrix.",
  returns = {{"number"}}}
fn{"Matrix:solve", doc = "X with A x = b (b a vector or a matrix); least squares when A is not square; an error when a square A is singular.",
  params = {{"b", "linalg.matrix"}},
  returns = {{"linalg.matrix"}}}
fn{"Matrix:pinv", doc = "Moore-Penrose pseudo-inverse (singular values below tol, default eps x max(r, c) x the largest, count as zero).",
  params = {{"tol?", "number"}},
  returns = {{"linalg.matrix"}}}
fn{"Matrix:svd", doc = "Thin SVD: A = U diag(s) Vᵀ, s a vector in descending order.",
  returns = {{"linalg.matrix", "U"}, {"linalg.matrix", "s"}, {"linalg.matrix", "V"}}}
fn{"Matrix:dls", doc = "Damped least squares `(AᵀA + λ²I)⁻¹Aᵀb`, solved through the smaller of AᵀA and AAᵀ.",
  params = {{"b", "linalg.matrix"}, {"lambda", "number"}},
  returns = {{"linalg.matrix"}}}
fn{"Matrix:norm", doc = "The Euclidean norm (the Frobenius norm for a matrix).",
  returns = {{"number"}}}
fn{"Matrix:dot", doc = "The dot product with a vector of the same size.",
  params = {{"w", "linalg.matrix"}},
  returns = {{"number"}}}
fn{"Matrix:cross", doc = "The cross product with another 3-vector.",
  params = {{"w", "linalg.matrix|number[]"}},
  returns = {{"linalg.matrix"}}}
fn{"Matrix:normalized", doc = "The vector scaled to unit length.",
  returns = {{"linalg.matrix"}}}
fn{"Matrix:copy", doc = "A copy.",
  returns = {{"linalg.matrix"}}}
fn{"Matrix:totable", doc = "Plain nested tables (rows), or a flat table for a vector.",
  returns = {{"table"}}}

class{"linalg.quat",
  doc = "A unit quaternion. q * r composes, q * v rotates a 3-vector.",
  operators = {"mul(linalg.quat): linalg.quat"},
  table = "local Quat = {}"}
fn{"Quat:rotate", doc = "The 3-vector v rotated by the quaternion (as `q * v`).",
  params = {{"v", "linalg.matrix|number[]"}},
  returns = {{"linalg.matrix"}}}
fn{"Quat:inv", doc = "The inverse rotation (the conjugate).",
  returns = {{"linalg.quat"}}}
fn{"Quat:matrix", doc = "The 3 x 3 rotation matrix.",
  returns = {{"linalg.matrix", "3 x 3 rotation"}}}
fn{"Quat:angle", doc = "The rotation angle, radians, 0 to pi.",
  returns = {{"number", "radians, 0..pi"}}}
fn{"Quat:totable", doc = "The quaternion as `{w, x, y, z}`.",
  returns = {{"number[]", "{w, x, y, z}"}}}

class{"linalg.transform",
  doc = "A rigid transform. T * U composes, T * v applies to a point.",
  operators = {"mul(linalg.transform): linalg.transform"},
  table = "local Transform = {}"}
fn{"Transform:inv", doc = "The inverse transform.",
  returns = {{"linalg.transform"}}}
fn{"Transform:rotation", doc = "The rotation part, a quaternion.",
  returns = {{"linalg.quat"}}}
fn{"Transform:translation", doc = "The translation part, a 3-vector.",
  returns = {{"linalg.matrix"}}}
fn{"Transform:matrix", doc = "The 4 x 4 homogeneous matrix.",
  returns = {{"linalg.matrix", "4 x 4 homogeneous"}}}
lua{"local linalg = {}"}
fn{"linalg.matrix", doc = "A matrix from its rows.",
  params = {{"rows", "number[][]"}},
  returns = {{"linalg.matrix"}}}
fn{"linalg.vector", doc = "A vector (an n x 1 column that stays a vector through products), or n zeros.",
  params = {{"entries", "number[]|integer"}},
  returns = {{"linalg.matrix"}}}
fn{"linalg.identity", doc = "The n x n identity matrix.",
  params = {{"n", "integer"}},
  returns = {{"linalg.matrix"}}}
fn{"linalg.zeros", doc = "A zero matrix of r x c, or a zero vector of r entries.",
  params = {{"r", "integer"}, {"c?", "integer"}},
  returns = {{"linalg.matrix"}}}
fn{"linalg.quat", doc = "A unit quaternion from w, x, y, z or a table `{w, x, y, z}` (normalised when made).",
  params = {{"w", "number|number[]"}, {"x?", "number"}, {"y?", "number"}, {"z?", "number"}},
  returns = {{"linalg.quat"}}}
fn{"linalg.quat_axis_angle", doc = "The unit quaternion turning `angle` radians about `axis` (normalised when made).",
  params = {{"axis", "linalg.matrix|number[]"}, {"angle", "number"}},
  returns = {{"linalg.quat"}}}
fn{"linalg.transform", doc = "A rigid transform from a quat or 3 x 3 rotation and a 3-vector (`{x, y, z}` tables work wherever a 3-vector is asked).",
  params = {{"R?", "linalg.quat|linalg.matrix"}, {"p?", "linalg.matrix|number[]"}},
  returns = {{"linalg.transform"}}}
lua{"return linalg"}

text[[Errors name the calling line and what was wrong: `behaviors/arm.lua:12: linalg: shape mismatch:
6x9 * 3x1`, `linalg: inv: singular matrix (3x3, rank 2)`, `linalg: get: index 4 out of range (the
vector has 3 entries)`, `linalg: matrix: entry (2, 1): expected a number, got string`. Storage
lives inside each value, so it counts against the VM's memory cap and needs no finalizer; work
that grows with the cube of a size (products, inverses, decompositions) is charged to the
instruction budget, so a huge decomposition faults like an endless loop. Cost, measured on the
2-core build machine (`tests/engine/script/linalg_binding_test.cpp`): one 6 x 9 `J:dls(e,
lambda)` called from Lua, the new result vector and its garbage collection included, takes
**0.7 µs** on a quiet machine and 1.0 µs of CPU time with other builds running beside it
(fixed-capacity storage for systems up to 16 x 16, no heap allocation inside): a thousand
modules each doing one per step cost about a millisecond. Sizes: 1 to 65,536 rows and columns, at most 2²⁴
entries.]]

section{"Kinematics", md = [[`local kin = require("kinematics")` (`lua/kinematics.lua`) builds the forward kinematics of a
connected structure from the module types' own data (`world.module_type`, `module.type_data`):
joint pivots and axes, dock frames, and `world.connect`'s mating rule (faces opposite, turned
orientation x 360°/symmetry about the normal), so it follows any change to a type file.

```lua
local s = kin.structure{
  modules = {{name = "base", type = world.module_type("elongated_dock")},
             {name = "arm", type = world.module_type("superbot")}},
  connections = {{"base", "front", "arm", "back", 0}},   -- as world.connect(a, da, b, db, o)
  base = "base", base_pose = {at = {0, 0, 0.05}, quat = {1, 0, 0, 0}},
}
local f = s:fk(q)                       -- q[i]: angle of s.dofs[i] ({module=, joint=, lower=, ...})
local p, quat = f:link_pose("arm", "front_outer")
local centre, normal = f:dock("arm", "front")
local J, tip = f:jacobian("arm", "front")   -- 3 x #s.dofs, rows of numbers
local torques, loads = s:gravity(q)     -- static joint torques and dock loads, base held
```

`tests/worlds/kinematics_chain.lua` checks it against the physics: a chain of four SuperBots and
two elongated docks joined by front, back, left, up and down docks in all four mating
orientations, posed at random angles from the seed, agrees with every simulated link pose
within 0.0002 mm and 0.0001° (asserted: 0.1 mm, 0.1°). `tests/worlds/kinematics_gravity.lua`
poses the arm of `worlds/arm_ik.lua` at random under gravity on the exact solver: the static
joint torques and dock loads of `s:gravity` equal the simulated `m:joint_torque` and `m:dock_load`
to 0.0001 N·m and N (asserted within 2%), and the Jacobian matches finite differences of the
forward kinematics.]]}

section{"Sensors", md = [[Read lazily (only when asked) and at most once per step (a second read in the step returns the
same value). Every module has `joint:<name>` (angle, rad; `"velocity"` as the second argument
gives rad/s) and `dock:<name>` (`{enabled=, engaged=, proximity=, bearing=}`: proximity is the
distance to the nearest compatible free dock of another module within 0.1 m, an IR-style reading,
or nil; bearing is the unit direction `{x,y,z}` to that dock in this dock's frame: x out of the
face, z its `up` reference, y = z × x; nil with the proximity).
Module types declare the rest (`sensors = {...}`, format in `assets/modules/superbot.lua`):

| sensor | reading |
|---|---|
| `accelerometer` | `{x,y,z}` m/s² in the sensor link's frame, gravity included (a level module at rest reads about (0, 0, 9.81)) |
| `gyro` | `{x,y,z}` rad/s in the link frame |
| `orientation` | `{w,x,y,z}` of the link (an oracle) |
| `position` | `{x,y,z}` world position of the link (an oracle) |
| `range:<name>` | ray-cast distance in metres from the link, or nil beyond range (the module's own bodies are not seen) |
| `contact:<link>` | true while the link touches anything |

SuperBot and ATRON carry an accelerometer, gyro, orientation, position and a contact sensor per
link; the Wheelbot a forward `range:front` (0.02 to 2 m), the same inertial sensors and
`contact:chassis`.]]}

section{"Percepts, actions and noise", md = [[Percepts turn sensor readings into what the behaviour sees; actions turn commands into what
the actuators do. Both are declared as global tables in the behaviour, checked when it loads (a
misspelt sensor, joint or field is an error naming the behaviour's file and line), and use the
noise models of `lua/noise.lua` (the global `noise` in behaviours):

```lua
percepts = {
  tilt = { sensor = "accelerometer", noise = noise.gaussian(0.05),
           map = function(a) return math.atan(a[1], a[3]) end },          -- any Lua value
  obstacle = { sensor = "range:front", noise = { noise.gaussian(0.01), noise.dropout(0.05) },
               map = function(d) return {distance = d, near = d < 0.3} end },
}
actions = { lift = { joint = "pitch", noise = noise.gaussian(0.01) },      -- mode "target" or "velocity"
            latch = { dock = "front" } }                                   -- true enables, false disables
function step(dt)
  local o = module.sense("obstacle")        -- nil when dropped out or nothing in range
  module.act("lift", o and o.near and 0.5 or 0)
end
```

Models (each percept or action gets its own instance, so drift and delay lines are not shared):
`gaussian(sigma)`, `uniform(half_width)`, `bias(b)`, `offset(sigma)` (a calibration error: drawn once
from N(0, sigma) per element, then kept), `drift(sigma)` (random walk, sigma per √s), `wander(sigma,
tau)` (a first-order Gauss–Markov error: spread sigma, correlation exp(−t/tau); a servo's tracking
error, a gyro's bias instability),
`dropout(p)` (nil with probability p), `quantise(step)`, `saturate(lo, hi)`, `delay(k)` (the
value k steps earlier), `stuck{at = t}` or `stuck{rate = p}` (the value freezes), `compose(...)`.
They act on numbers and element by element on vectors. Each percept and each action draws
from its own seeded stream, keyed by its name (`sim.stream("percept:tilt")`,
`sim.stream("action:lift")`), so the order of `module.sense`/`module.act` calls never changes
the numbers: `for name in pairs(actions) do module.act(name, v) end` gives the same run every
time. (A reloaded behaviour's streams start again from the beginning.) Invalid parameters (negative sigma, p outside [0, 1]) are errors at the calling line.
World scripts inject faults with `m:inject_fault{...}` at any time (`world.at`).]]}
