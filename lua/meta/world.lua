---@meta
-- LuaLS definitions of the world-script API (worlds/*.lua, tests/worlds/*.lua). Kept complete by
-- the ctest `luals_meta` (tests/cli/luals_meta.cmake), which fails when a bound name is missing.
-- Reference: README.md, "Lua API reference".

---@alias Vec3 {x: number, y: number, z: number, [1]: number, [2]: number, [3]: number}
---@alias Quat {w: number, x: number, y: number, z: number}

---A module in the world (world side).
---@class Module
---@field id integer 1, 2, ... in spawn order
---@field name string
---@field type string module type name
local Module = {}
---@return Vec3
function Module:position() end
---@return Quat
function Module:orientation() end
---@return Vec3 linear velocity, m/s
function Module:velocity() end
---@param link string
---@return Vec3
function Module:link_position(link) end
---A link's frame in the world: position and orientation.
---@param link string
---@return Vec3
---@return Quat
function Module:link_pose(link) end
---@param joint string
---@return number radians
function Module:joint_angle(joint) end
---@return table<string, number>
function Module:joint_angles() end
---Torque (N m) its motor applied over the last step, and whether it was saturated.
---@param joint string
---@return number torque
---@return boolean saturated
function Module:joint_torque(joint) end
---@param dock string
---@return {enabled: boolean, engaged: boolean, peer_module: integer?, peer_dock: string?}
function Module:dock_state(dock) end
---@param dock string
---@return Vec3
function Module:dock_position(dock) end
---@param dock string
---@return Vec3
function Module:dock_normal(dock) end
---@param dock string
---@return "male"|"female"|"genderless"
function Module:dock_gender(dock) end
---Load through the connection at this dock over the last step, or nil.
---@param dock string
---@return {force: number, torque: number}?
function Module:dock_load(dock) end
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
---@param fault {joint: string?, dock: string?, sensor: string?}
function Module:inject_fault(fault) end
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
---@return Vec3
function Body:position() end
---@return Quat
function Body:orientation() end
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
---@return integer nodes
function Cloth:count() end
---@return integer nx, integer ny
function Cloth:resolution() end
---@return {min: Vec3, max: Vec3}? bounds of the nodes, nil when a node is NaN
function Cloth:bounds() end
---@return Vec3 mean node velocity
function Cloth:velocity() end
---@param i integer node index, 1..count
---@return Vec3
function Cloth:node(i) end
---@return Vec3[] every node, node 1 first
function Cloth:positions() end
---Node i stays where it is now.
---@param i integer
function Cloth:pin(i) end
---@param i integer
function Cloth:unpin(i) end
---@param i integer
---@return boolean
function Cloth:pinned(i) end

---Fluid or debris particles (world.fluid, world.debris).
---@class Particles
local Particles = {}
---@return integer count particles in the system (never changes)
function Particles:count() end
---@return "fluid"|"debris"
function Particles:kind() end
---@return number radius of each particle (m, half the spacing)
function Particles:radius() end
---@return Vec3 min
---@return Vec3 max
function Particles:bounds() end
---@return Vec3 mean velocity (m/s)
function Particles:mean_velocity() end
---@return Vec3[] positions one {x, y, z} per particle, in no fixed order
function Particles:positions() end
---@param min number[] {x, y, z}
---@param max number[] {x, y, z}
---@return integer count particles inside the box
function Particles:count_in(min, max) end

---@class ShapeOptions
---@field at? number[] {x, y, z}
---@field rot? number[] {roll, pitch, yaw}
---@field mass? number 0 (default): static
---@field friction? number
---@field rolling_friction? number m: rolling and spinning resistance (default 0.0005 for dynamic bodies)
---@field velocity? number[]

---@class world
world = {}
---@param s {dt: number?, substeps: integer?, gravity: number[]?, seed: integer?, duration: number?, solver: ("pgs"|"exact")?, solver_iterations: integer?, joint_iterations: integer?, erp: number?, max_speed: number?, max_angular_speed: number?, bounds: number?, expect_faults: (boolean|integer)?}
function world.set(s) end
---@param g? {friction: number?, restitution: number?}
function world.ground(g) end
---@param o ShapeOptions|{size: number[]}
---@return Body
function world.box(o) end
---@param o ShapeOptions|{radius: number}
---@return Body
function world.sphere(o) end
---@param o ShapeOptions|{radius: number, length: number}
---@return Body
function world.cylinder(o) end
---A cylinder of `length` along its local z with hemispherical caps (length + 2 radius overall).
---@param o ShapeOptions|{radius: number, length: number}
---@return Body
function world.capsule(o) end
---The mesh's convex hull; with concave = true the triangles themselves (static only).
---@param o ShapeOptions|{file: string, scale: number?, concave: boolean?}
---@return Body
function world.mesh(o) end
---A cloth sheet through Bullet soft bodies; corners in order around the edge.
---@param o {corners: number[][], resolution: integer[]?, mass: number?, stiffness: number?, pinned: integer[]?, pinned_nodes: integer[]?, friction: number?, thickness: number?, color: number[]?}
---@return Cloth
function world.cloth(o) end

---Static terrain from a grayscale image: black at at.z, white at at.z + height, centred on (at.x, at.y).
---@param o {image: string, size: number[], height: number, at: number[]?, friction: number?}
---@return Heightfield
function world.heightfield(o) end

---A box filled with position-based fluid particles (Macklin and Mueller 2013), coupled both ways
---with bodies and modules.
---@param o {min: number[], max: number[], spacing: number?, density: number?, viscosity: number?, tension: number?, friction: number?, kinetic_friction: number?, damping: number?, iterations: integer?, substeps: integer?, kernel: number?, max_speed: number?}
---@return Particles
function world.fluid(o) end
---A box filled with granular debris (grains with friction), coupled both ways with bodies.
---@param o {min: number[], max: number[], spacing: number?, density: number?, friction: number?, kinetic_friction: number?, damping: number?, iterations: integer?, substeps: integer?, max_speed: number?}
---@return Particles
function world.debris(o) end
---@param type string a module type name or a module-type file
---@param o? {at: number[]?, rot: number[]?, quat: number[]?, name: string?, behavior: string?, params: table?, fixed: boolean?, joints: table<string|integer, number>?}
---@return Module
function world.spawn(type, o) end
---Moves m's connected component straight down (or up) until its lowest point is at height z.
---@param m Module
---@param z? number metres (default 0, the ground plane)
---@return number moved metres moved (+ up)
function world.place_on_ground(m, z) end
---@param a Module
---@param dock_a string
---@param b Module
---@param dock_b string
---@param orientation? integer quarter turns about the normal
function world.connect(a, dock_a, b, dock_b, orientation) end
---@return Module[]
function world.modules() end
---@param id_or_name integer|string
---@return Module?
function world.module(id_or_name) end
---@return Module[][]
function world.components() end
---@param c {eye: number[]?, target: number[]?, follow: Module?, fov: number?}
function world.camera(c) end
---@param c {loss: number?, delay: integer?, rate: integer?, max_bytes: integer?}
function world.channel(c) end
---@param format? "json"|"dot"
---@return string
function world.graph(format) end
---A module type's data (links, joints, docks; README, World scripts), loading it if needed.
---@param name string
---@return ModuleTypeData
function world.module_type(name) end
---@param since? number
---@return {time: number, event: string, module_a: integer, dock_a: string, module_b: integer, dock_b: string, force: number?, torque: number?}[]
function world.events(since) end
---@return {sent: integer, received: integer, dropped: integer}
function world.messages() end
---@param fn fun(t: number)
function world.on_step(fn) end
---Runs once when the run ends, however it ends.
---@param fn fun(t: number)
function world.on_end(fn) end
---@param t number
---@param fn fun(t: number)
function world.at(t, fn) end
---@param period number
---@param fn fun(t: number)
function world.every(period, fn) end
function world.stop() end
---@return number
function world.time() end
---@return number
function world.dt() end
---A series in --trace output.
---@param name string
---@param value number
function world.trace(name, value) end
---A named result under "metrics" in the JSON summary and sweep lines.
---@param name string
---@param value number|string|boolean
function world.metric(name, value) end

---A test assertion: a failure is recorded with file:line and the run goes on.
---@param cond any
---@param message? string
function expect(cond, message) end

---`--param key=value` pairs (numbers and true/false typed).
---@type table<string, string|number|boolean>
args = {}

---A line on stderr tagged with the time.
---@param ... any
function log(...) end
