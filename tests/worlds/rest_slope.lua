-- At rest on a slope: the ground tilted 10 deg (gravity turned about y, so down the slope is +x,
-- along a SuperBot's length), mu 0.8. From 0.5 s to 10.5 s a servo-held SuperBot and a
-- superbot_box move less than 0.5 mm and turn less than 0.1 deg (tan 10 deg = 0.18 is far inside
-- the cone). Before the friction per contact patch and its anchors, the SuperBot crept 3.7 mm and
-- turned 0.78 deg (docs/physics.md, "Contacts at rest").
local slope = math.rad(10)
world.set{duration = 10.5, gravity = {9.81 * math.sin(slope), 0, -9.81 * math.cos(slope)}}
world.ground{friction = 0.8}
-- The third, a SuperBot turned 90 deg, has the slope across it (it rolled 0.16 mm and 0.18 deg on
-- it while it rested on one bracket rim, before the brackets were made square).
local ms = {}
for i, kind in ipairs({"superbot", "superbot_box", "superbot"}) do
  ms[i] = world.spawn(kind, {at = {0, i - 1, 0.3}, rot = {0, 0, i == 3 and math.pi / 2 or 0}})
  world.place_on_ground(ms[i])
end
local p0, q0 = {}, {}
world.at(0.5, function()
  for i, m in ipairs(ms) do p0[i], q0[i] = m:position(), m:orientation() end
end)
world.on_end(function()
  for i, m in ipairs(ms) do
    local p, q = m:position(), m:orientation()
    local d = math.sqrt((p.x - p0[i].x) ^ 2 + (p.y - p0[i].y) ^ 2 + (p.z - p0[i].z) ^ 2)
    local w = q0[i].w * q.w + q0[i].x * q.x + q0[i].y * q.y + q0[i].z * q.z
    local turn = math.deg(2 * math.acos(math.min(1, math.abs(w))))
    expect(d < 0.0005, string.format("%s on the slope moved %.4f mm, expected under 0.5", m.type, d * 1000))
    expect(turn < 0.1, string.format("%s on the slope turned %.4f deg, expected under 0.1", m.type, turn))
    local name = ({"superbot_along", "superbot_box", "superbot_across"})[i]
    world.metric(name .. "_mm", d * 1000)
    world.metric(name .. "_deg", turn)
  end
end)
