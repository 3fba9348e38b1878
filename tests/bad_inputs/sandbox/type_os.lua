-- Sandbox probe: each attempt that gets through prints RM3D-ESCAPE or leaves a marker file
-- under /tmp/rm3d_bi_escape; the runner checks both. Ends by printing PROBE-DONE.
local ESC = "/tmp/rm3d_bi_escape"
local function escaped(what) print("RM3D-ESCAPE: " .. what) end
local function try(what, f)
  local ok, r = pcall(f)
  if ok and r then escaped(what .. " -> " .. tostring(r)) end
end
try("os.execute", function() return os.execute("touch " .. ESC .. "/os_execute") end)
try("os.getenv", function() return os.getenv("HOME") or os.getenv("PATH") end)
try("os.remove", function() return os.remove(ESC .. "/keep") end)
try("os.rename", function() return os.rename(ESC .. "/keep", ESC .. "/renamed") end)
try("os.tmpname", function() return os.tmpname() end)
try("os.exit", function() return os.exit(3) end)
return require("superbot")
