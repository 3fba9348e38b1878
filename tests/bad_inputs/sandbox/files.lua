-- Sandbox probe: each attempt that gets through prints RM3D-ESCAPE or leaves a marker file
-- under /tmp/rm3d_bi_escape; the runner checks both. Ends by printing PROBE-DONE.
local ESC = "/tmp/rm3d_bi_escape"
local function escaped(what) print("RM3D-ESCAPE: " .. what) end
local function try(what, f)
  local ok, r = pcall(f)
  if ok and r then escaped(what .. " -> " .. tostring(r)) end
end
try("dofile", function() return dofile("/tmp/rm3d_bi_evil/evil.lua") end)
try("loadfile", function() return loadfile("/tmp/rm3d_bi_evil/evil.lua") end)
try("load binary", function() return load(string.dump(function() return 1 end)) end)
try("load binary mode b", function() return load(string.dump(function() return 1 end), "x", "b") end)
try("load forged binary", function() return load("\27Lua\84\0\25\147\r\n\26\n\4\8\8" .. string.rep("\255", 64)) end)
try("load reader binary", function() local parts = {"\27", "Lua", string.dump(function() end):sub(5)} local i = 0 return load(function() i = i + 1 return parts[i] end) end)
print("PROBE-DONE")
function step(dt) end
