-- Self-reconfiguration's agreement stage (behaviors/reconfigure.lua): SuperBots docked as a snake
-- on the ground learn their shape from dock messages, agree through an echo wave that every one
-- holds the same map, and each computes the same plan to a legged walker, with no global state.
-- The world script only observes: every module must commit, to the same map digest and the same
-- plan text, which must equal the plan the world computes from world's own graph; the roles must
-- be the target's, each once; each module knows the operations it takes part in.
--
-- Checks, for --param modules=8 (the default; walker8), 16 or 32: the above, the plan's operations
-- equal to the fewest possible, everyone committed within 6n + 10 steps, and no operation run (the
-- snake is whole at the end). With --param churn=1, s3 lets go of s4 at step 3, while the maps are
-- still filling, and the two parts agree separately: each knows it cannot become the 8-module
-- walker (published "error"), and no module commits to a map it does not share.
-- Prints the plan, when the modules committed and the messages a module sent.
local reconfig = require("reconfig")
local n = args.modules or 8
local churn = args.churn == 1
if type(n) ~= "number" or n < 8 or n % 8 ~= 0 then
  error("--param modules: a multiple of 8, at least 8, got " .. tostring(args.modules))
end
world.set{dt = 1 / 60, duration = 0.25 + n * 0.1}
world.ground{friction = 0.8}

-- The target: a head and a body chain with legs in left/right pairs on the body's side docks
-- (n = 8: walker8, a head, a 3-module body and four legs on the first and last body modules).
local pairsOfLegs = math.max(2, n // 8)
local chainLength = n - 2 * pairsOfLegs
local roles, conns = {}, {}
for i = 1, chainLength do roles[i] = "c" .. i end
for i = 1, chainLength - 1 do conns[#conns + 1] = {"c" .. i, "back", "c" .. (i + 1), "front"} end
for k = 0, pairsOfLegs - 1 do
  local body = 2 + math.floor(k * (chainLength - 2) / (pairsOfLegs - 1) + 0.5)
  for _, side in ipairs({"left", "right"}) do
    local leg = "l" .. (2 * k + (side == "left" and 1 or 2))
    roles[#roles + 1] = leg
    conns[#conns + 1] = {"c" .. body, side, leg, "front"}
  end
end
local target = {modules = roles, connections = conns}
-- Module types matter to the plan: every role is a SuperBot.
local typed = {}
for _, r in ipairs(roles) do typed[r] = "superbot" end
target.modules = typed

local mods = {}
for i = 1, n do
  local p = {target = target, execute = false}
  if churn and i == 3 then p.leave_at = 2.5 / 60 end
  mods[i] = world.spawn("superbot", {name = "s" .. i, at = i == 1 and {0, 0, 0.05} or nil,
                                     behavior = "behaviors/reconfigure.lua", params = p})
  if i > 1 then world.connect(mods[i - 1], "back", mods[i], "front") end
end

local committedAt = {}
world.every(1 / 60, function(t)
  for i, m in ipairs(mods) do
    if not committedAt[i] and (m:published("committed") or m:published("error")) then
      committedAt[i] = math.floor(t * 60 + 0.5)
    end
  end
end)

world.on_end(function(t)
  if t <= 0 then return end
  for _, m in ipairs(mods) do
    expect(m:error() == nil, m.name .. " faulted: " .. tostring(m:error()))
  end
  if churn then
    -- Two parts, s1..s3 and s4..n: each agrees on its own map, and none can be the walker.
    local digests = {}
    for i, m in ipairs(mods) do
      local part = i <= 3 and 1 or 2
      local d = m:published("digest")
      expect(d ~= nil, m.name .. " committed to a map")
      digests[part] = digests[part] or d
      expect(d == digests[part], m.name .. " holds its part's map: " .. tostring(d) .. " against " .. tostring(digests[part]))
      local e = m:published("error") or ""
      expect(e:find("the shapes hold " .. (part == 1 and 3 or n - 3) .. " and " .. n .. " modules", 1, true) ~= nil,
             m.name .. " says why it cannot plan: " .. e)
    end
    expect(digests[1] ~= digests[2], "the two parts' maps differ")
    print(string.format("two parts agreed separately by step %d", math.max(table.unpack(committedAt))))
    return
  end

  -- The world's own plan, from its graph now (nothing has moved).
  local expected = reconfig.plan(reconfig.from_world(world), reconfig.shape(target))
  local text = reconfig.format(expected)
  local sent, last, used = 0, 0, {}
  for i, m in ipairs(mods) do
    expect(m:published("plan") == text, m.name .. "'s plan is the world's: " .. tostring(m:published("plan")))
    expect(m:published("digest") == mods[1]:published("digest"), m.name .. " holds s1's map")
    local role = m:published("role")
    expect(role ~= nil and typed[role] and not used[role], m.name .. " has a role of its own: " .. tostring(role))
    if role then used[role] = true end
    -- The operations it takes part in are exactly those naming it.
    local mine = {}
    for k, o in ipairs(expected.ops) do
      if o[1] == m.name or o[3] == m.name then mine[#mine + 1] = k end
    end
    local ops = m:published("ops") or {}
    expect(table.concat(ops, ",") == table.concat(mine, ","), m.name .. " knows its operations: " ..
           table.concat(ops, ",") .. " against " .. table.concat(mine, ","))
    sent = sent + (m:published("messages") or 0)
    last = math.max(last, committedAt[i] or math.huge)
  end
  expect(#expected.ops == expected.lower_bound, string.format("%d operations, the fewest is %d",
                                                               #expected.ops, expected.lower_bound))
  expect(last <= 6 * n + 10, string.format("every module committed by step %d (at most %d)", last, 6 * n + 10))
  expect(#world.components() == 1, "the snake is whole: no operation was run")
  print(text)
  print(string.format("%d modules committed by step %d (first at step %d); %.1f messages a module",
                      n, last, math.min(table.unpack(committedAt)), sent / n))
end)
