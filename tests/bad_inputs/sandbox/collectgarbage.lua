-- Sandbox probe: each attempt that gets through prints RM3D-ESCAPE or leaves a marker file
-- under /tmp/rm3d_bi_escape; the runner checks both. Ends by printing PROBE-DONE.
local ESC = "/tmp/rm3d_bi_escape"
local function escaped(what) print("RM3D-ESCAPE: " .. what) end
local function try(what, f)
  local ok, r = pcall(f)
  if ok and r then escaped(what .. " -> " .. tostring(r)) end
end
collectgarbage("stop")
try("generational", function() collectgarbage("generational", 0, 0) return nil end)
try("incremental", function() collectgarbage("incremental", 0, 0, 0) return nil end)
try("step huge", function() collectgarbage("step", 1e9) return nil end)
try("memory cap with gc stopped", function() local t = {} for i = 1, 1e7 do t[i] = {i} end return "allocated 10M tables" end)
collectgarbage("restart")
print("PROBE-DONE")
function step(dt) end
