-- For tests/worlds/range_sensor.lua: a Wheelbot at rest reads its forward range sensor raw
-- (module.sensor) and through percepts whose map returns a table, a string and a boolean, and
-- checks them against params.distance (the nominal distance from the chassis front face to the
-- obstacle, or false: out of range, must read nil). Any failed check is an error (the world sees
-- m:error()); after 20 good steps it disables its "back" dock, the signal the world reads.
local expected = params.distance   -- number, or false for "nothing within 2 m"
local kNear = 0.5

percepts = {
  obstacle = {sensor = "range:front",
              map = function(d) return {kind = "obstacle", distance = d, near = d < kNear} end},
  word = {sensor = "range:front", map = function(d) return d < kNear and "near" or "far" end},
  flag = {sensor = "range:front", map = function(d) return d < kNear end},
}

local good = 0

local function check(cond, fmt, ...)
  if not cond then error(string.format("t=%.3f: " .. fmt, sim.time(), ...), 2) end
end

function step(dt)
  if sim.time() < 0.1 then return end  -- let it settle on its wheels
  local d = module.sensor("range:front")
  local ob = module.sense("obstacle")
  local word, flag = module.sense("word"), module.sense("flag")
  if expected then
    check(type(d) == "number", "raw reading should be a number, got %s", tostring(d))
    check(math.abs(d - expected) < 0.001, "raw reading %.6f m, expected %.6f m (within 1 mm)", d, expected)
    check(type(ob) == "table", "percept should be a table, got %s", type(ob))
    check(ob.kind == "obstacle", "percept kind: %s", tostring(ob.kind))
    check(ob.distance == d, "percept distance %s differs from the raw reading %s (no noise declared)",
          tostring(ob.distance), tostring(d))
    check(ob.near == (d < kNear), "percept near flag: %s for %.3f m", tostring(ob.near), d)
    check(rawequal(module.sense("obstacle"), ob), "a second read in the same step should return the same table")
    check(word == (d < kNear and "near" or "far"), "string percept: %s", tostring(word))
    check(flag == (d < kNear), "boolean percept: %s", tostring(flag))
  else
    check(d == nil, "out of range: raw reading should be nil, got %s", tostring(d))
    check(ob == nil and word == nil and flag == nil, "out of range: percepts should be nil")
  end
  good = good + 1
  if good == 20 then module.dock("back"):disable() end
end
