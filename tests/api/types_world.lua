-- The API's declared types hold at run time: every world-side function of the API description
-- (docs/api/lua_api.lua) is called here with arguments of its declared types, and what it returns
-- is checked against its declared return types (tests/api/type_check.lua); every behaviour-side
-- function is called by tests/api/types_behaviour.lua in two docked SuperBots and a Wheelbot, which
-- publish what they checked. At the end every function of the description must have been checked
-- (a new binding fails this world until it is exercised here). Run by ctest api_types.
local T = require("type_check")
local linalg = require("linalg")
local check = T.check

world.set{dt = 1 / 60, duration = 1.0, seed = 5}
check("world.set", {{dt = 1 / 60}}, world.set{dt = 1 / 60})
check("world.ground", {{friction = 0.8, restitution = 0}}, world.ground{friction = 0.8, restitution = 0})

-- Obstacles and environments.
local box = check("world.box", {{size = {0.1, 0.1, 0.1}, at = {2, 0, 0.05}, mass = 0.5}},
                  world.box{size = {0.1, 0.1, 0.1}, at = {2, 0, 0.05}, mass = 0.5})
check("world.sphere", {{radius = 0.05, at = {2.3, 0, 0.05}}}, world.sphere{radius = 0.05, at = {2.3, 0, 0.05}})
check("world.cylinder", {{radius = 0.05, length = 0.1, at = {2.6, 0, 0.05}}},
      world.cylinder{radius = 0.05, length = 0.1, at = {2.6, 0, 0.05}})
check("world.capsule", {{radius = 0.03, length = 0.1, at = {2.9, 0, 0.2}}},
      world.capsule{radius = 0.03, length = 0.1, at = {2.9, 0, 0.2}})
check("world.mesh", {{file = "assets/meshes/rock.obj", scale = 0.1, at = {3.2, 0, 0.1}}},
      world.mesh{file = "assets/meshes/rock.obj", scale = 0.1, at = {3.2, 0, 0.1}})
local hf = check("world.heightfield", {{image = "assets/terrain/hills_30.png", size = {1, 1}, height = 0.1, at = {-3, 0, 0}}},
                 world.heightfield{image = "assets/terrain/hills_30.png", size = {1, 1}, height = 0.1, at = {-3, 0, 0}})
local corners = {{-2.2, 2.8, 0.5}, {-1.8, 2.8, 0.5}, {-1.8, 3.2, 0.5}, {-2.2, 3.2, 0.5}}
local cloth = check("world.cloth", {{corners = corners, resolution = {4, 4}}}, world.cloth{corners = corners, resolution = {4, 4}})
local fluid = check("world.fluid", {{min = {3, 3, 0}, max = {3.06, 3.06, 0.06}}},
                    world.fluid{min = {3, 3, 0}, max = {3.06, 3.06, 0.06}})
local debris = check("world.debris", {{min = {-3, -3, 0}, max = {-2.94, -2.94, 0.06}}},
                     world.debris{min = {-3, -3, 0}, max = {-2.94, -2.94, 0.06}})

-- Modules: two SuperBots docked side by side and a Wheelbot, all running the behaviour check.
local probe = "types_behaviour.lua"
local a = check("world.spawn", {"superbot", {name = "a", behavior = probe}},
                world.spawn("superbot", {name = "a", behavior = probe, params = {peer = "left"}}))
local b = world.spawn("superbot", {name = "b", behavior = probe, params = {peer = "right"}})
check("world.connect", {a, "left", b, "right"}, world.connect(a, "left", b, "right"))
check("world.place_on_ground", {a, 0}, world.place_on_ground(a, 0))
local w = world.spawn("wheelbot", {name = "w", at = {0, -1, 0.045}, behavior = probe})
-- A module for the supervisor's writes (push, set_dock, inject_fault).
local victim = world.spawn("superbot", {name = "victim", at = {0, 1, 0.043}})
-- Dock settings and placement: a magnet-docked pair placed 20 mm apart, face to face.
check("world.docks", {{capture = "magnet", capture_time = 5}}, world.docks{capture = "magnet", capture_time = 5})
local p1 = world.spawn("superbot", {name = "p1", at = {2, 2, 0.043}, docks = {capture = "joint", capture_force = 10}})
local p2 = world.spawn("superbot", {name = "p2", at = {2.5, 2, 0.043}})
check("world.place_facing", {p1, "back", p2, "front", 0.02, 0}, world.place_facing(p1, "back", p2, "front", 0.02, 0))
world.docks{}

check("world.camera", {{eye = {1, -1, 1}, target = {0, 0, 0}, fov = 50}}, world.camera{eye = {1, -1, 1}, target = {0, 0, 0}, fov = 50})
check("world.channel", {{loss = 0, delay = 0}}, world.channel{loss = 0, delay = 0})
check("world.module_type", {"superbot"}, world.module_type("superbot"))
check("world.modules", {}, world.modules())
check("world.module", {"a"}, world.module("a"))
check("world.module", {2}, world.module(2))
check("world.module", {"nobody"}, world.module("nobody"))
check("world.components", {}, world.components())
check("world.graph", {"json"}, world.graph("json"))
check("world.graph", {"dot"}, world.graph("dot"))
check("world.graph", {}, world.graph())
-- Each member of a declared union is accepted at run time.
T.acceptsEach("world.metric", 2, function(v) world.metric("union_" .. type(v), v) end)
T.acceptsEach("world.trace", 2, function(v) world.trace("union", v) end)
T.acceptsEach("world.module", 1, function(v) return world.module(v) end)
T.acceptsEach("world.graph", 1, function(v) return world.graph(v) end)
check("log", {"types_world: built"}, log("types_world: built"))
check("expect", {true, "a test assertion"}, expect(true, "a test assertion"))

local function handles(t)
  for _, m in ipairs({a, w}) do
    check("Module:position", {}, m:position())
    check("Module:orientation", {}, m:orientation())
    check("Module:velocity", {}, m:velocity())
    check("Module:link_position", {"front_outer"}, a:link_position("front_outer"))
    check("Module:link_pose", {"front_outer"}, a:link_pose("front_outer"))
    check("Module:joint_angles", {}, m:joint_angles())
    check("Module:error", {}, m:error())
    check("Module:published", {"checked"}, m:published("checked"))
    check("Module:published", {}, m:published())
    check("Module:sensor", {"orientation"}, m:sensor("orientation"))
    check("Module:dock_state", {"front"}, m:dock_state("front"))
    check("Module:dock_position", {"front"}, m:dock_position("front"))
    check("Module:dock_normal", {"front"}, m:dock_normal("front"))
    check("Module:dock_gender", {"front"}, m:dock_gender("front"))
    check("Module:dock_load", {"front"}, m:dock_load("front"))
  end
  check("Module:dock_load", {"left"}, a:dock_load("left"))
  check("Module:joint_angle", {"pitch"}, a:joint_angle("pitch"))
  check("Module:joint_torque", {"pitch"}, a:joint_torque("pitch"))
  check("Module:sensor", {"joint:pitch", "velocity"}, a:sensor("joint:pitch", "velocity"))
  check("Body:position", {}, box:position())
  check("Body:orientation", {}, box:orientation())
  check("Body:velocity", {}, box:velocity())
  check("Body:sleeping", {}, box:sleeping())
  check("Heightfield:height_at", {-3.0, 0.0}, hf:height_at(-3.0, 0.0))
  check("Heightfield:height_at", {50.0, 0.0}, hf:height_at(50.0, 0.0))
  check("Heightfield:position", {}, hf:position())
  check("Heightfield:orientation", {}, hf:orientation())
  check("Heightfield:velocity", {}, hf:velocity())
  check("Heightfield:count", {}, hf:count())
  check("Heightfield:resolution", {}, hf:resolution())
  check("Heightfield:bounds", {}, hf:bounds())
  check("Cloth:count", {}, cloth:count())
  check("Cloth:resolution", {}, cloth:resolution())
  check("Cloth:bounds", {}, cloth:bounds())
  check("Cloth:velocity", {}, cloth:velocity())
  check("Cloth:node", {1}, cloth:node(1))
  check("Cloth:positions", {}, cloth:positions())
  check("Cloth:pin", {5}, cloth:pin(5))
  check("Cloth:pinned", {5}, cloth:pinned(5))
  check("Cloth:unpin", {5}, cloth:unpin(5))
  for _, p in ipairs({fluid, debris}) do
    check("Particles:count", {}, p:count())
    check("Particles:kind", {}, p:kind())
    check("Particles:radius", {}, p:radius())
    check("Particles:bounds", {}, p:bounds())
    check("Particles:mean_velocity", {}, p:mean_velocity())
    check("Particles:positions", {}, p:positions())
    check("Particles:count_in", {{-10, -10, -1}, {10, 10, 1}}, p:count_in({-10, -10, -1}, {10, 10, 1}))
  end
  check("world.time", {}, world.time())
  check("world.dt", {}, world.dt())
  check("world.events", {}, world.events())
  check("world.events", {0.0}, world.events(0.0))
  check("world.messages", {}, world.messages())
  check("world.trace", {"t", t}, world.trace("t", t))
end

check("world.on_step", {function() end}, world.on_step(function(t) if t < 0.05 then handles(t) end end))
check("world.at", {0.5, function() end}, world.at(0.5, function(t)
  check("Module:push", {{0, 0, 1}}, victim:push({0, 0, 1}))
  check("Module:set_dock", {"front", false}, victim:set_dock("front", false))
  check("Module:inject_fault", {{joint = "pitch"}}, victim:inject_fault{joint = "pitch"})
  handles(t)
end))
check("world.every", {0.25, function() end}, world.every(0.25, function(t) world.trace("every", t) end))

-- linalg (require("linalg") in world scripts and behaviours alike).
local A = check("linalg.matrix", {{{2, 1}, {1, 3}}}, linalg.matrix{{2, 1}, {1, 3}})
local v = check("linalg.vector", {{1, 2}}, linalg.vector{1, 2})
check("linalg.vector", {3}, linalg.vector(3))
check("linalg.identity", {3}, linalg.identity(3))
check("linalg.zeros", {2, 3}, linalg.zeros(2, 3))
check("linalg.zeros", {2}, linalg.zeros(2))
check("Matrix:rows", {}, A:rows())
check("Matrix:cols", {}, A:cols())
check("Matrix:get", {1, 2}, A:get(1, 2))
check("Matrix:get", {2}, v:get(2))
check("Matrix:set", {1, 1, 4.0}, A:copy():set(1, 1, 4.0))
check("Matrix:t", {}, A:t())
check("Matrix:inv", {}, A:inv())
check("Matrix:det", {}, A:det())
check("Matrix:solve", {v}, A:solve(v))
check("Matrix:pinv", {}, A:pinv())
check("Matrix:pinv", {1e-9}, A:pinv(1e-9))
check("Matrix:svd", {}, A:svd())
check("Matrix:dls", {v, 0.1}, A:dls(v, 0.1))
local v3 = linalg.vector{1, 0, 0}
check("Matrix:norm", {}, v3:norm())
check("Matrix:dot", {v3}, v3:dot(v3))
check("Matrix:cross", {{0, 1, 0}}, v3:cross({0, 1, 0}))
check("Matrix:normalized", {}, v3:normalized())
check("Matrix:copy", {}, A:copy())
check("Matrix:totable", {}, A:totable())
local q = check("linalg.quat", {1, 0, 0, 0}, linalg.quat(1, 0, 0, 0))
check("linalg.quat", {{1, 0, 0, 0}}, linalg.quat{1, 0, 0, 0})
local q2 = check("linalg.quat_axis_angle", {{0, 0, 1}, 0.5}, linalg.quat_axis_angle({0, 0, 1}, 0.5))
check("Quat:rotate", {{1, 0, 0}}, q2:rotate({1, 0, 0}))
check("Quat:inv", {}, q:inv())
check("Quat:matrix", {}, q2:matrix())
check("Quat:angle", {}, q2:angle())
check("Quat:totable", {}, q2:totable())
local tf = check("linalg.transform", {q2, {1, 2, 3}}, linalg.transform(q2, {1, 2, 3}))
check("linalg.transform", {}, linalg.transform())
check("Transform:inv", {}, tf:inv())
check("Transform:rotation", {}, tf:rotation())
check("Transform:translation", {}, tf:translation())
check("Transform:matrix", {}, tf:matrix())

-- Callbacks the engine calls, not a script: on_reload needs a hot reload, which
-- tests/engine/world/hot_reload_test.cpp and tests/cli/watch_test.sh exercise; observe and act
-- are called by the Python API (tests/python/test_world.py).
local notCalledHere = {on_reload = true, observe = true, act = true}
-- world.reward and world.done: their functions run only under the Python API (tests/python).
check("world.reward", {function() return 0 end}, world.reward(function() return 0 end))
check("world.done", {function() return false end}, world.done(function() return false end))

check("world.on_end", {function() end}, world.on_end(function(t)
  check("world.metric", {"checked", 1}, world.metric("checked", 1))
  -- What the behaviours checked, and what went wrong there.
  for _, m in ipairs({a, b, w}) do
    local got = m:published("checked") or {}
    for name in pairs(got) do T.checked[name] = true end
    for _, f in ipairs(m:published("failures") or {}) do T.failures[#T.failures + 1] = m.name .. ": " .. f end
  end
  local reported = {}
  for _, f in ipairs(T.failures) do
    local text = f:gsub("^[%w_]+: ", "")  -- the same mismatch seen by several modules: once
    if not reported[text] then
      reported[text] = true
      expect(false, f)
    end
  end
  local missing = {}
  for name in pairs(T.declared) do
    if not T.checked[name] and not notCalledHere[name] then missing[#missing + 1] = name end
  end
  table.sort(missing)
  expect(#missing == 0, "functions of the API description never called here: " .. table.concat(missing, ", "))
  local n = 0
  for _ in pairs(T.checked) do n = n + 1 end
  print(string.format("api types: %d functions checked, %d type mismatches", n, #T.failures))
end))
world.at(0.9, function() check("world.stop", {}, world.stop()) end)
