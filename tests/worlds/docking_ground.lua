-- Docking on the ground: two SuperBots resting on the ground with docks facing latch through a
-- capture joint, front to back and front to front, with the gaps, lateral offsets and yaws of
-- issue 33's matrix; each pair latches within 3 s and the pair's centre moves less than 5 mm
-- before it latches. A pair 60 mm apart (outside the 30 mm capture radius) never latches.
-- `--param mu=0.3` runs it on slippery ground (ctest docking_ground_mu03); default mu 1.
local mu = args.mu or 1.0
world.set{duration = 3.5}
world.ground{friction = mu}

local cases = {}
local n = 0
local function case(kind, gap, lateral, yaw)
  n = n + 1
  local x0, y0 = 0, (n - 1) * 0.6  -- each pair on its own strip, far from the others
  local a = world.spawn("superbot", {at = {x0, y0, 0.1}, name = "a" .. n})
  local b
  if kind == "front-back" then
    -- b behind a, its front dock facing a's back dock
    local face = {x0 - 0.095 - gap, y0 + lateral}
    b = world.spawn("superbot", {at = {face[1] - 0.095 * math.cos(yaw), face[2] - 0.095 * math.sin(yaw), 0.1},
                                 rot = {0, 0, yaw}, name = "b" .. n})
  else
    -- b ahead of a, turned round, its front dock facing a's front dock
    local face = {x0 + 0.095 + gap, y0 + lateral}
    b = world.spawn("superbot", {at = {face[1] + 0.095 * math.cos(yaw), face[2] + 0.095 * math.sin(yaw), 0.1},
                                 rot = {0, 0, math.pi + yaw}, name = "b" .. n})
  end
  world.place_on_ground(a)
  world.place_on_ground(b)
  cases[#cases + 1] = {kind = kind, gap = gap, lateral = lateral, yaw = yaw, a = a, b = b,
                       dockA = kind == "front-back" and "back" or "front"}
end
for _, kind in ipairs({"front-back", "front-front"}) do
  for _, gap in ipairs({0.005, 0.015, 0.025}) do case(kind, gap, 0, 0) end
  case(kind, 0.015, 0.008, 0)
  case(kind, 0.015, 0, math.rad(15))
  case(kind, 0.025, 0.008, math.rad(-15))
end
case("front-back", 0.06, 0, 0)  -- outside the capture radius
local far = cases[#cases]

local function centre(c)
  local p, q = c.a:position(), c.b:position()
  return {x = (p.x + q.x) / 2, y = (p.y + q.y) / 2}
end
world.on_step(function(t)
  for _, c in ipairs(cases) do
    if not c.start and t >= 0.25 then c.start = centre(c) end  -- both have settled on their brackets
    if c.start and not c.latched and c.a:dock_state(c.dockA).engaged then
      c.latched = t
      local p = centre(c)
      c.moved = math.sqrt((p.x - c.start.x) ^ 2 + (p.y - c.start.y) ^ 2)
    end
  end
end)

world.on_end(function()
  local worst, slowest = 0, 0
  for i, c in ipairs(cases) do
    local what = string.format("%s, gap %.0f mm, lateral %.0f mm, yaw %.0f deg, mu %.1f", c.kind, c.gap * 1000,
                               c.lateral * 1000, math.deg(c.yaw), mu)
    if c ~= far then
      expect(c.latched and c.latched <= 3, what .. ": latched at " .. tostring(c.latched))
      expect(not c.moved or c.moved < 0.005, string.format("%s: the pair's centre moved %.2f mm before latching",
                                                          what, (c.moved or 0) * 1000))
      if c.latched then
        slowest = math.max(slowest, c.latched)
        worst = math.max(worst, c.moved)
      end
    end
  end
  expect(not far.latched, "a pair 60 mm apart latched")
  for _, m in ipairs(world.modules()) do expect(m:error() == nil, tostring(m:error())) end
  world.metric("latest_latch_s", slowest)
  world.metric("largest_centre_move_mm", worst * 1000)
  print(string.format("mu %.1f: %d pairs latched by %.2f s, centres moved at most %.2f mm", mu, #cases - 1,
                      slowest, worst * 1000))
end)
