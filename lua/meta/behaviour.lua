---@meta
-- LuaLS definitions of the behaviour API (behaviors/*.lua): the globals a module's VM gets.
-- Generated from docs/api/lua_api.lua by docs/api/generate.lua: edit that file, not this one.
-- Reference page: docs/api/lua.md.

---A joint of the module (module.joint(name)).
---@class Joint
local Joint = {}
---The joint's angle now, radians: the child link's rotation relative to its parent, right-handed about the joint axis.
---@return number radians, child relative to parent
function Joint:angle() end
---The joint's angular speed now, rad/s, with the sign of `angle`.
---@return number rad/s
function Joint:velocity() end
---The torque the motor (with the limit stop, when in contact) applied over the last step, N·m, and whether that was its full rating (it could not hold or reach its command).
---@return number torque
---@return boolean saturated
function Joint:torque() end
---True when the motor gave its full rating over the last step (it could not hold or reach its command); `torque` gives the torque too.
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
---Last servo target or nil.
---@return number? last servo target
function Joint:target() end
---Lower, upper.
---@return number lower
---@return number upper
function Joint:limits() end
---Name.
---@return string
function Joint:name() end

---A dock of the module (module.dock(name)).
---@class Dock
local Dock = {}
---True when the dock is willing to connect (`enable`/`disable`).
---@return boolean
function Dock:enabled() end
---True while the dock is latched to another.
---@return boolean
function Dock:engaged() end
---The dock's gender in the module type: `"male"` latches only to `"female"` and the reverse; `"none"` (genderless, as SuperBot's) only to `"none"`.
---@return "male"|"female"|"none"
function Dock:gender() end
---Makes the dock willing to connect: it latches to a facing willing dock within the capture limits.
function Dock:enable() end
---Makes the dock unwilling to connect; an engaged dock lets go (an undock).
function Dock:disable() end
---Queue a plain value (nil, boolean, number, string, tables of these; at most 64 KiB) for the module docked here, readable next step; false when nothing is engaged, or when this step's sends already fill 8 MiB (counted as dropped).
---@param value any nil, boolean, number, string, tables of these
---@return boolean sent false when nothing is engaged
function Dock:send(value) end
---The dock's name in the module type.
---@return string
function Dock:name() end
---While engaged, the module id and dock name it is latched to; nil otherwise.
---@return integer? peer module id
---@return string? peer dock name
function Dock:peer() end

---@class module
---@field id integer
---@field name string
---@field type string
module = {}
---The joint of this name (an error naming the type's joints when there is none).
---@param name string
---@return Joint
function module.joint(name) end
---The names of the module type's joints, in joint order.
---@return string[]
function module.joints() end
---This module's type as data (the table `world.module_type` gives), or that of another type a module of this world was spawned with.
---@param name? string
---@return ModuleTypeData
function module.type_data(name) end
---The dock of this name (an error naming the type's docks when there is none).
---@param name string
---@return Dock
function module.dock(name) end
---The names of the module type's docks, in dock order.
---@return string[]
function module.docks() end
---The oldest pending message (on that dock), consumed.
---@param dock? string
---@return {dock: string, data: any, time: number}?
function module.receive(dock) end
---A raw sensor reading this step (see Sensors).
---@param name string
---@param field? "velocity"
---@return any
function module.sensor(name, field) end
---Whether the type has that sensor (and, if not, what it has).
---@param name string
---@return boolean
---@return string? the sensors it has, when not
function module.has_sensor(name) end
---A declared percept's value this step.
---@param name string
---@return any
function module.sense(name) end
---A command through a declared action (see Percepts).
---@param name string
---@param value any
function module.act(name, value) end
---Records a number in the series `name` (column `trace.<name>` of this module's rows in `--trace`, and the viewer's plots); names are 1 to 64 letters, digits, `_`, `.`, `-`; the value a finite number; at most 256 names per behaviour.
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
---Simulated seconds since the start.
---@return number seconds since the start
function sim.time() end
---The control step, seconds (the world's `dt`).
---@return number the control step
function sim.dt() end
---A number from the module's own random stream, as `math.random` (`math.random` and `math.randomseed` use the stream too): [0, 1), or a whole number in [1, m] or [m, n].
---@param m? integer
---@param n? integer
---@return number
function sim.random(m, n) end
---A normal deviate from the module's own random stream, mean `mu` (default 0) and standard deviation `sigma` (default 1).
---@param mu? number
---@param sigma? number
---@return number
function sim.gaussian(mu, sigma) end
---A random stream of its own, seeded from the world seed, the module's stream and `key`: draws elsewhere never shift it (`stream.random()`, `stream.gaussian(mu, sigma)`, called with a dot).
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
---Called every control step (after `on_dock` events).
---@param dt number
function step(dt) end
---For the Python API (docs/python.md): the module's row of the `obs` array, a list of finite numbers (at most 4096). Without it the row is the joint angles (rad), the joint velocities (rad/s), then per dock 1 if engaged else 0. An error or a bad return faults the module.
---@return number[]
function observe() end
---For the Python API: called each step under `policy=True`, before `step(dt)`, with the module's row of the `act` array (`act_size` numbers; by default one per joint). Without it the row sets the joints' servo targets (rad). Whatever it sends through a dock arrives next step, as from `step`.
---@param a number[]
function act(a) end
---How many numbers `act(a)` takes, a whole number from 0 to 4096 (1.5 faults the module; it is never rounded); unset: the module's joint count.
---@type integer
act_size = nil
---Called after a hot reload replaced the behaviour's definitions (`state` survives).
function on_reload() end
---Called at the start of the module's next step for each dock event: `dock` is the Dock handle (compare `dock:name() == "front"`), `event` what happened: "engaged", "disengaged" or "broken"; and, before a connection exists, "captured" (a capture joint has begun drawing this dock and another together) and "stalled" (that capture has not latched after `capture_time`).
---@param dock Dock
---@param event "engaged"|"disengaged"|"broken"|"captured"|"stalled"
function on_dock(dock, event) end
