-- Bodies at rest stay at rest (docs/physics.md, "Contacts at rest"). Every shipped module type,
-- servos holding, put down with world.place_on_ground: from 0.5 s (settled on its contacts) to
-- 10.5 s it moves less than 0.5 mm and turns less than 0.1 deg. A SuperBot pushed sideways and
-- along its length with 1 N and 3 N for 3 s (mu m g = 5.6 N at mu 0.8) moves less than 0.5 mm;
-- pushed sideways with 12 N it slides. Default mu 0.8; `--param mu=0.3` (ctest rest_mu03) runs it on
-- slippery ground, where 12 N still slides and the pushes are left out (3 N is above mu m g).
local mu = args.mu or 0.8
world.set{duration = 10.5}
world.ground{friction = mu}

local function angle(q0, q1)
  local w = q0.w * q1.w + q0.x * q1.x + q0.y * q1.y + q0.z * q1.z
  return math.deg(2 * math.acos(math.min(1, math.abs(w))))
end

local checks = {}
local function add(kind, at, opts)
  local m = world.spawn(kind, {at = {at[1], at[2], 0.3}, name = opts.name})
  world.place_on_ground(m)
  checks[#checks + 1] = {m = m, push = opts.push, from = opts.from or 0.5, to = opts.to or 10.5,
                         slide = opts.slide, limit = opts.limit or 0.0005}
end
local x = 0
for _, kind in ipairs({"superbot", "superbot_box", "atron", "wheelbot", "elongated_dock"}) do
  add(kind, {x, 0}, {name = kind})
  x = x + 1
end
if mu >= 0.8 then
  add("superbot", {0, 2}, {name = "pushed_1N", push = {1, 0, 0}, to = 3.5})
  add("superbot", {1, 2}, {name = "pushed_3N", push = {3, 0, 0}, to = 3.5})
  add("superbot", {0, 4}, {name = "pushed_sideways_1N", push = {0, 1, 0}, to = 3.5})
  add("superbot", {1, 4}, {name = "pushed_sideways_3N", push = {0, 3, 0}, to = 3.5})
end
add("superbot", {2, 2}, {name = "pushed_12N", push = {0, 12, 0}, to = 3.5, slide = true})

world.on_step(function(t)
  for _, c in ipairs(checks) do
    if t >= c.from and not c.p0 then c.p0, c.q0 = c.m:position(), c.m:orientation() end
    if c.push and t >= c.from and t < c.to then c.m:push(c.push) end
    if t >= c.to - 1e-9 and not c.p1 then c.p1, c.q1 = c.m:position(), c.m:orientation() end
  end
end)

world.on_end(function()
  for _, c in ipairs(checks) do
    local d = math.sqrt((c.p1.x - c.p0.x) ^ 2 + (c.p1.y - c.p0.y) ^ 2 + (c.p1.z - c.p0.z) ^ 2)
    local turn = angle(c.q0, c.q1)
    local what = string.format("%s at mu %.1f over %.1f s", c.m.name, mu, c.to - c.from)
    if c.slide then
      expect(d > 0.05, string.format("%s: pushed above mu m g it slides (moved %.1f mm)", what, d * 1000))
    else
      expect(d < c.limit, string.format("%s: moved %.4f mm, expected under %.1f", what, d * 1000, c.limit * 1000))
      if not c.push then
        expect(turn < 0.1, string.format("%s: turned %.4f deg, expected under 0.1", what, turn))
      end
    end
    world.metric(c.m.name .. "_mm", d * 1000)
    world.metric(c.m.name .. "_deg", turn)
  end
end)
