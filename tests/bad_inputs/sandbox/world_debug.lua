world.set{duration = 0.1}
-- Sandbox probe: each attempt that gets through prints RM3D-ESCAPE or leaves a marker file
-- under /tmp/rm3d_bi_escape; the runner checks both. Ends by printing PROBE-DONE.
local ESC = "/tmp/rm3d_bi_escape"
local function escaped(what) print("RM3D-ESCAPE: " .. what) end
local function try(what, f)
  local ok, r = pcall(f)
  if ok and r then escaped(what .. " -> " .. tostring(r)) end
end
try("debug.sethook", function() debug.sethook(); return "hook removed" end)
try("debug.getregistry", function() return debug.getregistry() end)
try("debug.upvalue", function() return debug.getupvalue(require, 1) end)
try("collectgarbage budget", function() return (function() local n = 0 for i = 1, 5e7 do n = n + i end return nil end)() end)
print("PROBE-DONE")
