-- Sandbox probe: each attempt that gets through prints RM3D-ESCAPE or leaves a marker file
-- under /tmp/rm3d_bi_escape; the runner checks both. Ends by printing PROBE-DONE.
local ESC = "/tmp/rm3d_bi_escape"
local function escaped(what) print("RM3D-ESCAPE: " .. what) end
local function try(what, f)
  local ok, r = pcall(f)
  if ok and r then escaped(what .. " -> " .. tostring(r)) end
end
try("shared global", function() local seen = rawget(_G, "rm3d_bi_leak") rm3d_bi_leak = true return seen end)
try("world global", function() return rawget(_G, "rm3d_bi_world_leak") end)
try("shared string metatable", function() local s = getmetatable("").__index.rm3d_bi_mark getmetatable("").__index.rm3d_bi_mark = true return s end)
print("PROBE-DONE")
function step(dt) end
