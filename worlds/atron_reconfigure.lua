-- Self-reconfiguration with ATRONs: one module moves across the lattice, planned and carried out
-- by the modules themselves through dock messages (docs/self-reconfiguration.md).
--
-- Four ATRONs in zero gravity, as the ATRON simulator ran its reconfigurations: `b` holds `a` on
-- its south hemisphere and `c` on its north; `d` hangs on `c`. Every module runs
-- behaviors/reconfigure.lua and knows only the target shape: `a` docked to `d` instead of `b`.
-- They learn the shape from dock messages, agree on it, and each computes the same plan
-- (lua/reconfig.lua: undock a-b, dock a-d) and the same steps (lua/atron_moves.lua): `b` turns its
-- south hemisphere 180 degrees, carrying `a` to the lattice site next to `d` where a.s1 faces
-- d.s0; the capture joint draws them together and they latch; `a` lets go of `b`. (A quarter turn
-- would bring `a` to a site where its docks face `d`'s male to male: the genders' rule in
-- assets/modules/atron.lua.)
--
-- The checks: the plan and steps as above, the target shape at the end (lua/reconfig.lua finds no
-- operation left), no step failed, no connection broke, no module faulted; `a` ends a lattice
-- step (0.11 m) from `d`. With the defaults the modules agree on the plan at 0.32 s and the target
-- shape stands at 5.02 s.
--
-- `--param fault=1` breaks a's dock s1 first (m:inject_fault): it never latches. The turn then
-- goes back and tries again, once, and fails; every module stops with the reason. The checks
-- become: every module says the same reason, b turned twice, and a still hangs on b.
--
--   ./build/rm3d run worlds/atron_reconfigure.lua --png out/atron_reconfigure.png
local kFault = (args.fault or 0) ~= 0
local kDuration = kFault and 22 or 10
world.set{duration = kDuration, gravity = {0, 0, 0}}
local reconfig = require("reconfig")

local names = {"a", "b", "c", "d"}
local mods = {}
for _, n in ipairs(names) do mods[n] = "atron" end
local target = {modules = mods, connections = {{"a", "s1", "d", "s0"}, {"b", "n2", "c", "s1"}, {"c", "n1", "d", "n0"}}}

local m = {}
for i, n in ipairs(names) do
  m[n] = world.spawn("atron", {name = n, at = i == 2 and {0, 0, 0.3} or nil, behavior = "behaviors/reconfigure.lua",
                               params = {target = target}})
end
world.connect(m.b, "s0", m.a, "n1")
world.connect(m.b, "n2", m.c, "s1")
world.connect(m.c, "n1", m.d, "n0")
if kFault then m.a:inject_fault{dock = "s1"} end

local shown, done, broken, seen = false, nil, 0, nil
local peak = {force = 0, torque = 0}
local byId = {}
for _, n in ipairs(names) do byId[m[n].id] = n end
world.on_step(function(t)
  if not shown and m.a:published("steps") then
    shown = true
    print("plan\n" .. m.a:published("plan"))
    print("steps:\n" .. m.a:published("steps"))
  end
  local events = world.events()
  for i = (seen or #events) + 1, #events do  -- (the connections made before the first step are not news)
    local e = events[i]
    print(string.format("%s %s.%s - %s.%s", e.event, byId[e.module_a], e.dock_a, byId[e.module_b], e.dock_b))
  end
  seen = #events
  for _, n in ipairs(names) do
    for _, d in ipairs({"n0", "n1", "n2", "n3", "s0", "s1", "s2", "s3"}) do
      local l = m[n]:dock_load(d)
      if l then peak = {force = math.max(peak.force, l.force), torque = math.max(peak.torque, l.torque)} end
    end
  end
  if not done and #reconfig.plan(reconfig.from_world(world), reconfig.shape(target)).ops == 0 then
    done = t
    print(string.format("the target shape at t = %.2f s", t))
  end
end)

world.on_end(function(t)
  for _, n in ipairs(names) do expect(m[n]:error() == nil, n .. " did not fault: " .. tostring(m[n]:error())) end
  if t < kDuration then return end  -- a shorter run (the sample test's 2 s) checks only the faults
  local sent = 0
  for _, n in ipairs(names) do sent = sent + (m[n]:published("messages") or 0) end
  print(string.format("peak dock load %.1f N, %.3f N m; %.1f messages a module", peak.force, peak.torque, sent / #names))
  world.metric("reconfigured_s", done or -1)
  world.metric("peak_force_n", peak.force)
  world.metric("messages_per_module", sent / #names)
  for _, e in ipairs(world.events()) do
    if e.event == "broken" then broken = broken + 1 end
  end
  expect(broken == 0, broken .. " connections broke")
  if kFault then
    local why = "a.s1 did not latch to d.s0 within 3 s of the turn, 2 turns"
    for _, n in ipairs(names) do
      expect(m[n]:published("failed") == why, n .. " stopped with the reason: " .. tostring(m[n]:published("failed")))
    end
    expect(m.b:published("retries") == 1, "b turned back and tried again once")
    local st = m.a:dock_state("n1")
    expect(st.engaged and st.peer_module == m.b.id and st.peer_dock == "s0", "a still hangs on b")
    return
  end
  local failed
  for _, n in ipairs(names) do failed = failed or m[n]:published("failed") or m[n]:published("error") end
  expect(failed == nil, "no step failed: " .. tostring(failed))
  expect(done ~= nil, "the target shape was reached")
  expect(m.a:published("steps") ==
         " 1. turn    b turns its south hemisphere 180 deg: a.s1 docks to d.s0\n 2. release a lets go of b (n1-s0)",
         "the steps: b's half turn, then a lets go of b")
  local pa, pd = m.a:position(), m.d:position()
  local gap = math.sqrt((pa.x - pd.x) ^ 2 + (pa.y - pd.y) ^ 2 + (pa.z - pd.z) ^ 2)
  expect(math.abs(gap - 0.11) < 0.002, string.format("a is a lattice step from d: %.4f m", gap))
  expect(peak.force < 70 and peak.torque < 7, string.format("dock loads within 70%% of the docks' strength: %.1f N, %.2f N m",
                                                            peak.force, peak.torque))
end)
