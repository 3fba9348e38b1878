-- One behaviour for every module of the coupling cars (worlds/atron_cars.lua): it drives the
-- module's equator for the car's current mode and runs the small coupling protocol over the
-- docks.
--
-- params
--   car            the car this module belongs to ("tug", "car", ...)
--   solo           equator speed (rad/s) while the car drives on its own (nil: hold the equator
--                  at 0, as a chassis module does)
--   coupled        equator speed once the cars are coupled (nil: hold at 0)
--   released       equator speed after the release (nil: hold at 0; "brake": velocity 0 where
--                  it stands)
--   leaves         true: on "release" this module disables its docks that hold the other car
--   lead           true: this module orders the release ...
--   release_after  ... this many seconds after it heard that the cars coupled
--
-- Protocol. A dock that engages at run time sends {kind = "hello", car = ...} to its peer; a
-- hello from another car means the two cars have coupled through that dock (it is remembered
-- as a foreign dock), and "coupled" is flooded through the whole (now joined) vehicle: each
-- module acts on a kind once and passes it on over its other engaged docks, one hop a step.
-- The lead floods "release" later and every module switches to its `released` speed; modules
-- with `leaves` disable their foreign docks one step after passing "release" on (so it crosses
-- before the cut), which releases those connections in that step.
local equator = module.joint("equator")
local names = module.docks()
local docks = {}
for i, n in ipairs(names) do docks[i] = module.dock(n) end

local mode = "solo"
local seen = {}     -- flood kinds this module has acted on
local foreign = {}  -- names of docks that hold a module of another car
local coupledAt
local dropNext      -- disable the foreign docks at the start of the next step

local function flood(kind, except)
  for i, d in ipairs(docks) do
    if names[i] ~= except and d:engaged() then d:send({kind = kind, car = params.car}) end
  end
end

local function act(kind, from)
  if seen[kind] then return end
  seen[kind] = true
  if kind == "coupled" then
    mode = "coupled"
    coupledAt = sim.time()
  elseif kind == "release" then
    mode = "released"
    dropNext = params.leaves
  end
  flood(kind, from)
end

function on_dock(dock, event)
  if event == "engaged" then
    dock:send({kind = "hello", car = params.car})
  elseif event == "disengaged" or event == "broken" then
    log("dock " .. dock:name() .. " " .. event)
  end
end

function step(dt)
  if dropNext then
    -- One step after passing "release" on: a connection cut in the step a message is sent
    -- drops that message, so the other car hears the release before it is let go.
    dropNext = false
    for _, n in ipairs(foreign) do
      module.dock(n):disable()
      log("release: disabled dock " .. n)
    end
  end
  while true do
    local msg = module.receive()
    if not msg then break end
    local m = msg.data
    if type(m) == "table" and m.kind == "hello" then
      if m.car ~= params.car then
        foreign[#foreign + 1] = msg.dock
        log("coupled to the " .. m.car .. " through dock " .. msg.dock)
        act("coupled", nil)
      end
    elseif type(m) == "table" and (m.kind == "coupled" or m.kind == "release") then
      act(m.kind, msg.dock)
    end
  end
  if params.lead and coupledAt and sim.time() >= coupledAt + (params.release_after or 3) then
    act("release", nil)
  end
  local speed = params[mode]
  if speed == nil then
    equator:set_target(0)
  elseif speed == "brake" then
    equator:set_velocity(0)
  else
    equator:set_velocity(speed)
  end
end
