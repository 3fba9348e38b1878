-- Sandbox probe: each attempt that gets through prints RM3D-ESCAPE or leaves a marker file
-- under /tmp/rm3d_bi_escape; the runner checks both. Ends by printing PROBE-DONE.
local ESC = "/tmp/rm3d_bi_escape"
local function escaped(what) print("RM3D-ESCAPE: " .. what) end
local function try(what, f)
  local ok, r = pcall(f)
  if ok and r then escaped(what .. " -> " .. tostring(r)) end
end
try("package.loadlib", function() return package.loadlib("libc.so.6", "system") end)
try("package.cpath", function() return package.cpath end)
try("package.searchers", function() return package.searchers[3]("x") end)
try("require io", function() return require("io").open end)
try("require os", function() return require("os").execute end)
try("require debug", function() return require("debug").sethook end)
try("require ffi", function() return require("ffi") end)
print("PROBE-DONE")
function step(dt) end
