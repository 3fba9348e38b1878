-- Checks run-time values against the LuaLS types the API declares (docs/api/lua_api.lua, through
-- the generated api_types.lua): unions a|b, optional T?, arrays T[], table<K, V>, table shapes
-- {k: T, ...}, literal strings, fun(...), the built-in types and the API's classes and aliases.
-- Used by tests/api/types_world.lua and tests/api/types_behaviour.lua.
local M = {}

M.declared = require("api_types")

-- Splits s at top-level occurrences of the separator character (outside {}, (), <>, []).
local function splitTop(s, sep)
  local parts, depth, start = {}, 0, 1
  for i = 1, #s do
    local c = s:sub(i, i)
    if c == "{" or c == "(" or c == "<" or c == "[" then
      depth = depth + 1
    elseif c == "}" or c == ")" or c == ">" or c == "]" then
      depth = depth - 1
    elseif c == sep and depth == 0 then
      parts[#parts + 1] = s:sub(start, i - 1)
      start = i + 1
    end
  end
  parts[#parts + 1] = s:sub(start)
  return parts
end

local function trim(s)
  return (s:gsub("^%s+", ""):gsub("%s+$", ""))
end

local function isNumber3(v)
  return type(v) == "table" and type(v.x or v[1]) == "number" and type(v.y or v[2]) == "number" and
             type(v.z or v[3]) == "number"
end

-- A handle of one of the API's classes: userdata or table answering the class's methods.
local function hasMethods(v, ...)
  if type(v) ~= "userdata" and type(v) ~= "table" then return false end
  for _, m in ipairs({...}) do
    local ok, f = pcall(function() return v[m] end)
    if not ok or type(f) ~= "function" then return false end
  end
  return true
end

local classes = {
  Vec3 = isNumber3,
  Quat = function(v)
    return type(v) == "table" and type(v.w) == "number" and type(v.x) == "number" and type(v.y) == "number" and
               type(v.z) == "number"
  end,
  Module = function(v) return hasMethods(v, "position", "joint_angle", "dock_state") end,
  Body = function(v) return hasMethods(v, "position", "sleeping") end,
  Heightfield = function(v) return hasMethods(v, "height_at", "resolution") end,
  Cloth = function(v) return hasMethods(v, "node", "pin") end,
  Particles = function(v) return hasMethods(v, "count_in", "mean_velocity") end,
  Joint = function(v) return hasMethods(v, "angle", "set_target") end,
  Dock = function(v) return hasMethods(v, "engaged", "send", "name") end,
  RandomStream = function(v)
    return type(v) == "table" and type(v.random) == "function" and type(v.gaussian) == "function"
  end,
  ModuleTypeData = function(v)
    return type(v) == "table" and type(v.name) == "string" and type(v.links) == "table" and
               type(v.joints) == "table" and type(v.docks) == "table"
  end,
  -- Option tables: their fields are checked by the world functions themselves.
  ShapeOptions = function(v) return type(v) == "table" end,
  DockSettings = function(v) return type(v) == "table" end,
  ["linalg.matrix"] = function(v) return hasMethods(v, "rows", "cols", "solve") end,
  ["linalg.quat"] = function(v) return hasMethods(v, "rotate", "angle") end,
  ["linalg.transform"] = function(v) return hasMethods(v, "rotation", "translation") end,
}

local matches

-- {k: T, k2: T2?, [1]: number}: every named field's value matches its type.
local function matchShape(v, body)
  if type(v) ~= "table" then return false, "expected a table" end
  for _, field in ipairs(splitTop(body, ",")) do
    field = trim(field)
    if field ~= "" then
      local key, t = field:match("^(%b[])%s*:%s*(.+)$")
      local value
      if key then
        value = v[tonumber(key:sub(2, -2))]
      else
        key, t = field:match("^([%w_]+)%s*:%s*(.+)$")
        if not key then error("cannot read the table type field '" .. field .. "'") end
        value = v[key]
      end
      local ok, why = matches(value, trim(t))
      if not ok then return false, "field " .. key .. ": " .. why end
    end
  end
  return true
end

-- True when v is of type t; else false and why.
function matches(v, t)
  t = trim(t)
  local alts = splitTop(t, "|")
  if #alts > 1 then
    local whys = {}
    for _, a in ipairs(alts) do
      local ok, why = matches(v, a)
      if ok then return true end
      whys[#whys + 1] = why
    end
    return false, table.concat(whys, " / ")
  end
  if t:sub(-1) == "?" then
    if v == nil then return true end
    return matches(v, t:sub(1, -2))
  end
  if t:sub(1, 1) == "(" and t:sub(-1) == ")" then return matches(v, t:sub(2, -2)) end
  if t:sub(-2) == "[]" then
    if type(v) ~= "table" then return false, "expected an array (" .. t .. "), got " .. type(v) end
    for i, e in ipairs(v) do
      local ok, why = matches(e, t:sub(1, -3))
      if not ok then return false, "entry " .. i .. ": " .. why end
    end
    return true
  end
  if t:sub(1, 1) == '"' then
    return v == t:sub(2, -2), "expected " .. t .. ", got " .. tostring(v)
  end
  if t:sub(1, 1) == "{" then return matchShape(v, t:sub(2, -2)) end
  local k, val = t:match("^table<(.+)>$")
  if k then
    if type(v) ~= "table" then return false, "expected " .. t .. ", got " .. type(v) end
    local kv = splitTop(k, ",")
    for key, value in pairs(v) do
      local ok1, why1 = matches(key, kv[1])
      local ok2, why2 = matches(value, kv[2])
      if not ok1 then return false, "key: " .. why1 end
      if not ok2 then return false, "value at " .. tostring(key) .. ": " .. why2 end
    end
    return true
  end
  if t:match("^fun%(") then return type(v) == "function", "expected a function, got " .. type(v) end
  if t == "any" then return true end
  if t == "integer" then return math.type(v) == "integer", "expected an integer, got " .. tostring(v) end
  if t == "number" or t == "string" or t == "boolean" or t == "table" or t == "nil" or t == "function" then
    return type(v) == t, "expected " .. t .. ", got " .. type(v) .. " (" .. tostring(v) .. ")"
  end
  local class = classes[t]
  if class then return class(v), "expected a " .. t .. ", got " .. type(v) .. " (" .. tostring(v) .. ")" end
  error("the type checker does not know the type '" .. t .. "'")
end
M.matches = matches

M.checked = {}
M.failures = {}

local seen = {}
local function fail(name, msg)  -- each distinct mismatch once, however often the call is made
  local text = name .. ": " .. msg
  if seen[text] then return end
  seen[text] = true
  M.failures[#M.failures + 1] = text
end

-- Records that `name` was called (with arguments of its declared types: `args`) and checks what it
-- returned against its declared returns: each value's type, and no more values than declared.
function M.check(name, args, ...)
  local d = M.declared[name]
  if not d then
    fail(name, "not in the API description")
    return ...
  end
  M.checked[name] = true
  for i, p in ipairs(d.params) do
    local optional = p[1]:sub(-1) == "?"
    if p[1] ~= "..." and not (optional and args[i] == nil) then
      local ok, why = matches(args[i], p[2])
      if not ok then fail(name, "argument " .. p[1] .. " is not of its declared type: " .. why) end
    end
  end
  local n = select("#", ...)
  if n > #d.returns then
    fail(name, "returned " .. n .. " values, " .. #d.returns .. " declared")
  end
  for i, t in ipairs(d.returns) do
    local ok, why = matches((select(i, ...)), t)
    if not ok then fail(name, "return " .. i .. " (" .. t .. "): " .. why) end
  end
  return ...
end

-- Every alternative of a parameter's declared union is accepted: for each primitive member of
-- the declared type of parameter `index` (number, integer, string, boolean), call(sample) must
-- not raise. (A union that declares more than the binding takes misleads editors' checks.)
local samples = {number = 1.5, integer = 2, string = "text", boolean = true}
function M.acceptsEach(name, index, call)
  local d = M.declared[name]
  local t = d and d.params[index] and d.params[index][2]
  if not t then
    fail(name, "no parameter " .. index .. " in the API description")
    return
  end
  for _, alt in ipairs(splitTop(t:gsub("%?$", ""), "|")) do
    local sample = samples[trim(alt)]
    if sample ~= nil then
      local ok, err = pcall(call, sample)
      if not ok then
        fail(name, "parameter " .. d.params[index][1] .. " is declared " .. t .. " but a " .. trim(alt) ..
                       " is refused: " .. tostring(err))
      end
    end
  end
end

-- Calls fn(args...) (a method when `self` is given) and checks it; returns what it returned.
function M.call(name, f, args)
  return M.check(name, args, f(table.unpack(args, 1, args.n or #args)))
end

return M
