-- Prints every name a world VM binds, and spawns a module running probe_behaviour.lua.
world.set{duration = 0.05}
local std = {}
for n in ("_G _VERSION assert collectgarbage error getmetatable ipairs load next pairs pcall print rawequal " ..
          "rawget rawlen rawset require select setmetatable tonumber tostring type xpcall warn coroutine math " ..
          "string table utf8"):gmatch("%S+") do std[n] = true end
local function names(t, skip)
  local out = {}
  for k in pairs(t) do
    if type(k) == "string" and not (skip and skip[k]) and not k:match("^__") then out[#out + 1] = k end
  end
  table.sort(out)
  return table.concat(out, " ")
end
print("LUALS world " .. names(world))
print("LUALS world_globals " .. names(_G, std))
world.spawn("superbot", {behavior = "probe_behaviour.lua"})
