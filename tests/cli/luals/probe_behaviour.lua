-- Prints every name a behaviour VM binds (tests/cli/luals_meta.cmake checks lua/meta/ has each).
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
local told = false
function step()
  if told then return end
  told = true
  log("LUALS module " .. names(module))
  log("LUALS sim " .. names(sim))
  log("LUALS behaviour_globals " .. names(_G, std))
end
