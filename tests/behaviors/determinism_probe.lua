-- For tests/engine/world/determinism_test.cpp: a behaviour that touches everything a behaviour
-- can touch, every step, so that any race or order dependence changes the world's state. It
-- reads every sensor of its type (joints, every dock's proximity, accelerometer, gyro,
-- orientation, position, range, contact), toggles its back dock on a pattern, sends what it read
-- over its engaged docks and relays what it receives, draws from its random stream and from a
-- noise model, and drives its joints from all of that.
percepts = {
  tilt = {sensor = "orientation", noise = noise.gaussian(0.01)},
}

local names = {}
local docks = {}
local sensors = {}

function init()
  for _, j in ipairs(module.joints()) do names[#names + 1] = j end
  for _, d in ipairs(module.docks()) do docks[#docks + 1] = module.dock(d) end
  local _, list = module.has_sensor("?")  -- false and the type's sensor names
  for name in list:gmatch("[^, ]+") do sensors[#sensors + 1] = name end
  state.sum = 0
  state.heard = 0
end

local function add(v)
  if type(v) == "number" then
    state.sum = state.sum + v
  elseif type(v) == "table" then
    -- Fields by name: pairs() order over string keys differs between VMs (Lua seeds its string
    -- hash per state), and floating-point sums depend on order.
    for _, k in ipairs({"w", "x", "y", "z"}) do if v[k] then state.sum = state.sum + v[k] end end
  elseif v == true then
    state.sum = state.sum + 1
  end
end

function step(dt)
  local n = math.floor(sim.time() / dt + 0.5)
  -- Toggle the back dock first: when dock states could change during the phase, what other
  -- modules' proximity sensors saw depended on which behaviours had run before them.
  local back = module.dock(params.toggle or "back")
  if (n + module.id) % 3 == 0 then back:disable() else back:enable() end
  add(back:enabled())
  -- Every sensor, every step: dock proximity reads the other modules' dock states.
  for _, name in ipairs(sensors) do
    local r = module.sensor(name)
    if type(r) == "table" and r.proximity ~= nil then
      add(r.proximity)
      if r.engaged then add(1) end
    else
      add(r)
    end
  end
  add(module.sense("tilt"))
  -- Messages: what it read, over every engaged dock; relay what it hears once.
  for _, d in ipairs(docks) do
    if d:engaged() then d:send({from = module.id, sum = state.sum % 1000, n = n}) end
  end
  while true do
    local msg = module.receive()
    if not msg then break end
    state.heard = state.heard + 1
    add(msg.data.sum)
  end
  -- Joints follow a wave bent by everything above.
  local wobble = (state.sum % 1) * 0.2 + sim.gaussian(0, 0.05) + 0.1 * math.random()
  for i, j in ipairs(names) do
    module.joint(j):set_target(0.1 * math.sin(2 * sim.time() + module.id + i) + 0.2 * wobble)
  end
end
