-- Run-time docking respects genders: an ATRON whose female dock faces another's male dock 1 cm
-- away is pulled in and latches; turned a quarter turn about its axis, so that a male dock faces
-- the male, it never docks.
world.set{gravity = {0, 0, 0}, duration = 1.5}
local vec = require("vec")
-- Where a module docked at n0 sits relative to its partner: found with a probe pair.
local pa = world.spawn("atron", {at = {0, 10, 0}})
local pb = world.spawn("atron", {at = {1, 10, 0}})
world.connect(pa, "n0", pb, "s1")
local rel = vec.sub(vec.v3(pb:position()), vec.v3(pa:position()))
local q = vec.q4(pb:orientation())
local n = vec.v3(pa:dock_normal("n0"))
local function place(y, quat)
  local a = world.spawn("atron", {at = {0, y, 0}})
  local b = world.spawn("atron", {at = vec.add({rel[1], rel[2] + y, rel[3]}, vec.scale(n, 0.01)), quat = quat})
  return a, b
end
local a1, b1 = place(0, q)                                                   -- female faces the male
local a2, b2 = place(2, vec.qmul(q, vec.qaxis({0, 0, 1}, math.pi / 2)))      -- quarter turn: male faces male
world.at(0.02, function()
  local g1 = b1:dock_gender("s1")
  expect(g1 == "female", "b1 presents its female s1, got " .. g1)
  local toward = function(m)  -- the dock of m facing back towards a
    for _, d in ipairs({"n0", "n1", "n2", "n3", "s0", "s1", "s2", "s3"}) do
      if vec.dot(vec.v3(m:dock_normal(d)), n) < -0.999 then return d end
    end
  end
  expect(b2:dock_gender(toward(b2)) == "male", "b2 presents a male dock")
end)
world.at(1.4, function()
  local s = a1:dock_state("n0")
  expect(s.engaged and s.peer_module == b1.id and s.peer_dock == "s1", "male and female latched at run time")
  expect(not a2:dock_state("n0").engaged, "two males never dock")
  for _, d in ipairs({"n0", "n1", "n2", "n3", "s0", "s1", "s2", "s3"}) do
    expect(not b2:dock_state(d).engaged, "the turned module docked nowhere")
  end
end)
