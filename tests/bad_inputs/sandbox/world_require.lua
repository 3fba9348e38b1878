world.set{duration = 0.1}
-- Sandbox probe: each attempt that gets through prints RM3D-ESCAPE or leaves a marker file
-- under /tmp/rm3d_bi_escape; the runner checks both. Ends by printing PROBE-DONE.
local ESC = "/tmp/rm3d_bi_escape"
local function escaped(what) print("RM3D-ESCAPE: " .. what) end
local function try(what, f)
  local ok, r = pcall(f)
  if ok and r then escaped(what .. " -> " .. tostring(r)) end
end
for _, name in ipairs({"/tmp/rm3d_bi_evil/evil", "/tmp/rm3d_bi_evil/evil.lua", ".tmp.rm3d_bi_evil.evil",
    "..tmp.rm3d_bi_evil.evil", "../../../../../../../../tmp/rm3d_bi_evil/evil",
    "behaviors/../../../../../../../../tmp/rm3d_bi_evil/evil", "..", "...", ".", "/etc/passwd",
    "../../../../../../../../etc/passwd", "tmp/rm3d_bi_evil/evil", "evil"}) do
  try("require " .. name, function() local r = require(name) return r == "evil loaded" and r end)
end
print("PROBE-DONE")
