-- Helpers for ATRON lattice worlds: `local atron = require("atron")` (see assets/modules/atron.lua
-- for the dock layout).
local vec = require("vec")
local atron = {}

atron.docks = {"n0", "n1", "n2", "n3", "s0", "s1", "s2", "s3"}
atron.male = {n0 = true, n2 = true, s0 = true, s2 = true}

--- The dock of module m whose outward normal points along dir.
function atron.dock_toward(m, dir)
  local n = vec.norm(dir)
  for _, d in ipairs(atron.docks) do
    if vec.dot(vec.v3(m:dock_normal(d)), dir) / n > 0.999 then return d end
  end
  error("no dock of " .. m.name .. " points that way", 2)
end

--- Where the OUTER pole of a module docked at a's dock da will point. With ATRON's poleward dock
--- `up` references, a dock normal n = (P + t)/sqrt2, P being a's pole on that side, puts the new
--- module's inner pole along -t, so its outer pole lies along t = sqrt2 n - P.
function atron.outer_pole(a, da)
  local n = vec.v3(a:dock_normal(da))
  local z = vec.qrot(a:orientation(), {0, 0, 1})
  local s = da:sub(1, 1) == "n" and 1 or -1
  return {math.sqrt(2) * n[1] - s * z[1], math.sqrt(2) * n[2] - s * z[2], math.sqrt(2) * n[3] - s * z[3]}
end

--- World scripts: expect() that every connection recorded as {a = Module, da = dock, b = Module,
--- db = dock} is still engaged between those two docks.
function atron.expect_connected(connections)
  for _, c in ipairs(connections) do
    local s = c.a:dock_state(c.da)
    expect(s.engaged and s.peer_module == c.b.id and s.peer_dock == c.db,
           string.format("%s.%s is still docked to %s.%s", c.a.name, c.da, c.b.name, c.db))
  end
end

return atron
