-- Sandbox probe: each attempt that gets through prints RM3D-ESCAPE or leaves a marker file
-- under /tmp/rm3d_bi_escape; the runner checks both. Ends by printing PROBE-DONE.
local ESC = "/tmp/rm3d_bi_escape"
local function escaped(what) print("RM3D-ESCAPE: " .. what) end
local function try(what, f)
  local ok, r = pcall(f)
  if ok and r then escaped(what .. " -> " .. tostring(r)) end
end
try("io.open write", function() return io.open(ESC .. "/io_write", "w"):write("x") end)
try("io.open read", function() return io.open("/etc/hostname"):read("a") end)
try("io.popen", function() return io.popen("touch " .. ESC .. "/popen") end)
try("io.lines", function() return io.lines("/etc/hostname")() end)
print("PROBE-DONE")
function step(dt) end
