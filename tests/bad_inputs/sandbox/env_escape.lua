-- Sandbox probe: each attempt that gets through prints RM3D-ESCAPE or leaves a marker file
-- under /tmp/rm3d_bi_escape; the runner checks both. Ends by printing PROBE-DONE.
local ESC = "/tmp/rm3d_bi_escape"
local function escaped(what) print("RM3D-ESCAPE: " .. what) end
local function try(what, f)
  local ok, r = pcall(f)
  if ok and r then escaped(what .. " -> " .. tostring(r)) end
end
try("load env", function() return load("return io", "x", "t", nil)() end)
try("getmetatable string", function() return getmetatable("").__index.dump and load(getmetatable("").__index.dump(print)) end)
try("_ENV swap", function() local _ENV = setmetatable({}, {__index = _G}) return os end)
print("PROBE-DONE")
function step(dt) end
