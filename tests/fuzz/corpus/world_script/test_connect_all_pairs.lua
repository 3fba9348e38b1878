-- world.connect mates every pair of SuperBot docks (36 pairs) face to face: centres within
-- 1 mm and normals opposite within 1 degree, before and after a second of stepping.
world.set{gravity = {0, 0, 0}, duration = 1}
local names = {"front", "back", "left", "right", "up", "down"}
local pairs_ = {}
local k = 0
for _, da in ipairs(names) do
  for _, db in ipairs(names) do
    local a = world.spawn("superbot", {at = {(k % 6) * 1.0, (k // 6) * 1.0, 1}})
    local b = world.spawn("superbot", {at = {(k % 6) * 1.0, (k // 6) * 1.0, 2}})
    world.connect(a, da, b, db, k % 4)
    pairs_[#pairs_ + 1] = {a = a, da = da, b = b, db = db}
    k = k + 1
  end
end
local function check(when)
  for _, p in ipairs(pairs_) do
    local pa, pb = p.a:dock_position(p.da), p.b:dock_position(p.db)
    local na, nb = p.a:dock_normal(p.da), p.b:dock_normal(p.db)
    local gap = math.sqrt((pa.x - pb.x) ^ 2 + (pa.y - pb.y) ^ 2 + (pa.z - pb.z) ^ 2)
    local dot = -(na.x * nb.x + na.y * nb.y + na.z * nb.z)
    local angle = math.deg(math.acos(math.min(1, dot)))
    local label = string.format("%s %s-%s", when, p.da, p.db)
    expect(gap < 0.001, string.format("%s: face centres %.4f m apart", label, gap))
    expect(angle < 1, string.format("%s: normals %.3f deg from opposite", label, angle))
    local s = p.a:dock_state(p.da)
    expect(s.engaged and s.peer_module == p.b.id and s.peer_dock == p.db, label .. ": dock state shows the peer")
  end
end
check("at start")
world.at(1, function() check("after 1 s") end)
expect(#pairs_ == 36, "36 pairs")
