-- Obstacles: static and dynamic boxes, spheres, cylinders and a mesh's convex hull come to rest
-- where they should (heights within 2 mm), and a static body does not move.
world.set{duration = 2}
world.ground{friction = 0.8}
local table_ = world.box{size = {0.4, 0.4, 0.1}, at = {0, 0, 0.05}}                  -- static
local ball = world.sphere{radius = 0.05, at = {0, 0, 0.4}, mass = 0.2}                 -- lands on it
local can = world.cylinder{radius = 0.03, length = 0.12, at = {1, 0, 0.061}, mass = 0.1} -- stands
local brick = world.box{size = {0.2, 0.1, 0.05}, at = {2, 0, 0.5}, rot = {0, 0, 0.7}, mass = 0.5}
local plate = world.mesh{file = "assets/meshes/superbot_end_plate.obj", at = {3, 0, 0.2}, rot = {0, math.pi / 2, 0},
                         mass = 0.05}

world.at(2, function()
  local function near(b, z, what)
    local p = b:position()
    expect(math.abs(p.z - z) < 0.002, string.format("%s rests at z=%.4f, expected %.4f", what, p.z, z))
  end
  near(ball, 0.15, "the ball on the table")
  near(can, 0.06, "the cylinder")
  near(brick, 0.025, "the brick")
  near(plate, 0.006, "the end plate (a convex hull lying flat)")
  local t = table_:position()
  expect(math.abs(t.x) + math.abs(t.y) + math.abs(t.z - 0.05) < 1e-6, "the static table stays put")
  local v = ball:velocity()
  expect(math.abs(v.z) < 0.01, "the ball is at rest")
end)
