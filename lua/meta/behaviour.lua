---@meta
-- LuaLS definitions of the behaviour API (behaviors/*.lua): the globals a module's VM gets. Kept
-- complete by the ctest `luals_meta` (tests/cli/luals_meta.cmake). Reference: README.md.

---A joint of the module (module.joint(name)).
---@class Joint
local Joint = {}
---@return number radians, child relative to parent
function Joint:angle() end
---@return number rad/s
function Joint:velocity() end
---Torque (N m) applied over the last step, and whether it was saturated.
---@return number torque
---@return boolean saturated
function Joint:torque() end
---@return boolean
function Joint:saturated() end
---Position servo within limits, torque and speed.
---@param rad number
function Joint:set_target(rad) end
---Velocity drive within torque and speed.
---@param rad_s number
function Joint:set_velocity(rad_s) end
---Motor off.
function Joint:free() end
---@return number? last servo target
function Joint:target() end
---@return number lower
---@return number upper
function Joint:limits() end
---@return string
function Joint:name() end

---A dock of the module (module.dock(name)).
---@class Dock
local Dock = {}
---@return boolean
function Dock:enabled() end
---@return boolean
function Dock:engaged() end
---@return "male"|"female"|"genderless"
function Dock:gender() end
function Dock:enable() end
function Dock:disable() end
---Queues a plain value for the module docked here (readable next step).
---@param value any nil, boolean, number, string, tables of these
---@return boolean sent false when nothing is engaged
function Dock:send(value) end
---@return string
function Dock:name() end
---@return integer? peer module id
---@return string? peer dock name
function Dock:peer() end

---@class module
---@field id integer
---@field name string
---@field type string
module = {}
---@param name string
---@return Joint
function module.joint(name) end
---@return string[]
function module.joints() end
---This module's type as data, or that of another type spawned in the world.
---@param name? string
---@return ModuleTypeData
function module.type_data(name) end
---@param name string
---@return Dock
function module.dock(name) end
---@return string[]
function module.docks() end
---The oldest pending message (on that dock), consumed.
---@param dock? string
---@return {dock: string, data: any, time: number}?
function module.receive(dock) end
---A raw sensor reading this step ("accelerometer", "joint:pitch", "range:front", ...).
---@param name string
---@param field? "velocity"
---@return any
function module.sensor(name, field) end
---@param name string
---@return boolean
---@return string? the sensors it has, when not
function module.has_sensor(name) end
---A declared percept's value this step (noise and map applied), or nil.
---@param name string
---@return any
function module.sense(name) end
---A command through a declared action (map and noise applied).
---@param name string
---@param value any
function module.act(name, value) end
---A series in --trace output.
---@param name string
---@param value number
function module.trace(name, value) end
---Makes a plain value (at most 64 KiB) readable by the world script as m:published(key), until
---published again; nil removes the key. Keys: 1 to 64 letters, digits, _ . -; at most 256.
---@param key string
---@param value any
function module.publish(key, value) end

---@class RandomStream
---@field random fun(m?: integer, n?: integer): number
---@field gaussian fun(mu?: number, sigma?: number): number

---@class sim
sim = {}
---@return number seconds since the start
function sim.time() end
---@return number the control step
function sim.dt() end
---Like math.random, from the module's own seeded stream.
---@param m? integer
---@param n? integer
---@return number
function sim.random(m, n) end
---@param mu? number
---@param sigma? number
---@return number
function sim.gaussian(mu, sigma) end
---A stream of its own, seeded from the world seed, the module's stream and `key`.
---@param key string
---@return RandomStream
function sim.stream(key) end

---A copy of the spawn params.
---@type table<string, any>
params = {}
---A table for your own state; survives hot reload.
---@type table
state = {}
---Noise models (lua/noise.lua).
noise = require("noise")

---@class PerceptSpec
---@field sensor string
---@field field? "velocity"
---@field noise? table a noise model or a list of them
---@field map? fun(v: any): any
---@type table<string, PerceptSpec>
percepts = {}

---@class ActionSpec
---@field joint? string
---@field dock? string
---@field mode? "target"|"velocity"
---@field noise? table
---@field map? fun(v: any): any
---@type table<string, ActionSpec>
actions = {}

---Callbacks a behaviour may define.
function init() end
---@param dt number
function step(dt) end
function on_reload() end
---@param dock string
---@param event "engaged"|"disengaged"|"broken"
function on_dock(dock, event) end
