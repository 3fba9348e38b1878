-- Analytic check: a box sliding down an incline of angle theta with friction mu accelerates at
-- g (sin theta - mu cos theta), within 2%. The incline is the flat ground with gravity tilted by
-- theta about y (the same thing seen from the slope). Bullet combines the two friction
-- coefficients by multiplication, so mu = ground friction x box friction = 1.0 x 0.3 = 0.3; with
-- theta = 30 deg the expected acceleration is 9.81 (0.5 - 0.3 x 0.866) = 2.357 m/s^2. Measured
-- from the box's velocity along the slope at 0.5 s and 1.5 s (it starts at rest, resting on the
-- ground). `--param solver=pgs` runs it on the old solver.
if args.solver then world.set{solver = args.solver} end
local g, theta, mu_ground, mu_box = 9.81, math.rad(30), 1.0, 0.3
local mu = mu_ground * mu_box
world.set{duration = 1.6, gravity = {g * math.sin(theta), 0, -g * math.cos(theta)}}
world.ground{friction = mu_ground}
local box = world.box{size = {0.1, 0.1, 0.1}, at = {0, 0, 0.05}, mass = 1, friction = mu_box}
local expected = g * (math.sin(theta) - mu * math.cos(theta))

local v1
world.at(0.5, function() v1 = box:velocity() end)
world.at(1.5, function(t)
  local v2 = box:velocity()
  local a = (v2.x - v1.x) / 1.0
  local p = box:position()
  log(string.format("acceleration %.4f m/s^2, expected %.4f (mu = %.2f, theta = 30 deg): %+.3f%%;"
                      .. " sideways %.2e m/s, lift %.2e m", a, expected, mu, 100 * (a - expected) / expected,
                    v2.y, p.z - 0.05))
  expect(math.abs(a - expected) < 0.02 * expected,
         string.format("acceleration %.4f m/s^2, expected g(sin - mu cos) = %.4f m/s^2 within 2%% (off by %+.2f%%)",
                       a, expected, 100 * (a - expected) / expected))
  expect(math.abs(p.z - 0.05) < 0.002, string.format("the box stays on the ground (z = %.4f m)", p.z))
end)
