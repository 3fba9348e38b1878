-- Analytic check: free fall. A box dropped from rest falls g t^2 / 2. Physics integrates with
-- semi-implicit Euler in n substeps of h = dt / substeps (v += g h, then z += v h), so after n
-- substeps the drop is exactly g h^2 n (n + 1) / 2 and the speed g h n: both are asserted within
-- 0.1% of that. The continuous formula g t^2 / 2 is short of it by exactly 1/n (0.42% at t = 1 s
-- with 4 substeps of dt 1/60, set here because n must be known), so the drop is
-- asserted within 1/n + 0.1% of it. `--param solver=pgs` runs it on the old solver.
if args.solver then world.set{solver = args.solver} end
local substeps = 4
world.set{duration = 1.5, substeps = substeps}
local g, z0 = 9.81, 20.0
local box = world.box{size = {0.1, 0.1, 0.1}, at = {0, 0, z0}, mass = 1}

world.at(1.0, function(t)
  local h = world.dt() / substeps
  local n = math.floor(t / h + 0.5)
  local drop = z0 - box:position().z
  local v = -box:velocity().z
  local discrete = g * h * h * n * (n + 1) / 2
  local continuous = g * t * t / 2
  log(string.format("t=%.4f s, n=%d: drop %.6f m; g h^2 n(n+1)/2 = %.6f m (%+.4f%%); g t^2/2 = %.6f m (%+.4f%%);"
                      .. " speed %.5f m/s (g t %+.4f%%)", t, n, drop, discrete, 100 * (drop - discrete) / discrete,
                    continuous, 100 * (drop - continuous) / continuous, v, 100 * (v - g * h * n) / (g * h * n)))
  expect(math.abs(drop - discrete) < 0.001 * discrete,
         string.format("drop %.6f m, expected %.6f m (g h^2 n(n+1)/2) within 0.1%%", drop, discrete))
  expect(math.abs(drop - continuous) < (1 / n + 0.001) * continuous,
         string.format("drop %.6f m, expected g t^2/2 = %.6f m within 1/n + 0.1%%", drop, continuous))
  expect(math.abs(v - g * h * n) < 0.001 * g * h * n,
         string.format("speed %.5f m/s, expected g t = %.5f m/s within 0.1%%", v, g * h * n))
end)
