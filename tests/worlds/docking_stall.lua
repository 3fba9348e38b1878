-- A capture that cannot close: two SuperBots on the ground with docks facing 20 mm apart and a
-- fixed plate between the faces. The capture joint draws them against the plate and stops there
-- (bounded force and speed): nothing latches, nothing is flung away, and after the docks'
-- capture_time (3 s) the world reports the capture as stalled, with the distance and angle left,
-- as a "stalled" event and to both behaviours' on_dock.
world.set{duration = 4}
world.ground{friction = 0.8}
local heard = {}
local a = world.spawn("superbot", {at = {0, 0, 0.1}, name = "a", behavior = "../behaviors/dock_events.lua"})
local b = world.spawn("superbot", {at = {-0.19 - 0.02, 0, 0.1}, name = "b", behavior = "../behaviors/dock_events.lua"})
world.place_on_ground(a)
world.place_on_ground(b)
world.box{size = {0.006, 0.2, 0.12}, at = {-0.095 - 0.01, 0, 0.06}}  -- a 6 mm plate between the faces
local pa, pb = a:position(), b:position()
world.on_end(function()
  local captured, stalled
  for _, e in ipairs(world.events()) do
    if e.event == "captured" then captured = e end
    if e.event == "stalled" then stalled = e end
  end
  expect(captured and captured.time < 0.1, "the capture began at once")
  expect(stalled and math.abs(stalled.time - (captured.time + 3)) < 0.05,
         "the capture is reported stalled 3 s after it began: " .. tostring(stalled and stalled.time))
  expect(stalled and stalled.distance > 0.005 and stalled.distance < 0.03 and stalled.angle >= 0,
         string.format("the stalled event says what is left: %s m, %s rad", tostring(stalled and stalled.distance),
                       tostring(stalled and stalled.angle)))
  expect(not a:dock_state("back").engaged, "nothing latched through the plate")
  for _, m in ipairs({{a, pa}, {b, pb}}) do
    local p = m[1]:position()
    local d = math.sqrt((p.x - m[2].x) ^ 2 + (p.y - m[2].y) ^ 2 + (p.z - m[2].z) ^ 2)
    expect(d < 0.02, string.format("%s stayed by the plate (moved %.1f mm)", m[1].name, d * 1000))
  end
  for _, m in ipairs({a, b}) do
    expect(m:published("captured") == 1 and m:published("stalled") == 1,
           m.name .. " heard on_dock 'captured' and 'stalled' once each")
  end
end)
