-- Limits hold inside everything a behaviour can reach: a strict-mode _G, pcall around an
-- endless loop, coroutines, a backtracking pattern, an endless __gc, require outside the Lua
-- folders, invalid UTF-8 in an error. Each faults only its own module with file:line; a
-- neighbour keeps stepping; a too-large spawn params is an error naming the world file's line.
world.set{duration = 0.6, expect_faults = 8}
local function spawn(x, file)
  return world.spawn("superbot", {at = {x, 0, 1}, behavior = "../behaviors/" .. file})
end
local strict = spawn(0, "strict_globals.lua")
local pcalls = spawn(1, "pcall_loop.lua")
local coros = spawn(2, "coroutine_split.lua")
local pattern = spawn(3, "pattern_bomb.lua")
local gc = spawn(4, "gc_bomb.lua")
local req = spawn(5, "require_escape.lua")
local utf = spawn(6, "bad_utf8.lua")
local late = spawn(7, "late_error.lua")

local ok, err = pcall(function()
  return world.spawn("superbot", {at = {8, 0, 1}, params = {blob = string.rep("x", 5 * 1024 * 1024)}})
end)
expect(not ok and tostring(err):find("lua_limits.lua:%d+: .*params: value too large"), "params limit: " .. tostring(err))

local function has(m, ...)
  local e = tostring(m:error())
  for _, needle in ipairs({...}) do
    if not e:find(needle, 1, true) then return false end
  end
  return true
end

world.at(0.2, function()
  expect(strict:error() == nil, "strict _G: callbacks found without tripping __index: " .. tostring(strict:error()))
  expect(has(pcalls, "instruction budget exceeded", "pcall_loop.lua:"), "pcall loop: " .. tostring(pcalls:error()))
  expect(has(coros, "instruction budget exceeded", "coroutine_split.lua:"), "coroutines: " .. tostring(coros:error()))
  expect(has(pattern, "instruction budget exceeded in pattern matching", "pattern_bomb.lua:4:"), "pattern: " .. tostring(pattern:error()))
  expect(has(gc, "__gc is not allowed", "gc_bomb.lua:3:"), "__gc: " .. tostring(gc:error()))
  expect(has(req, "bad module name '.tmp.x'", "require_escape.lua:3:"), "require: " .. tostring(req:error()))
  expect(has(utf, "bad_utf8.lua:3: bad byte \u{FFFD} here"), "utf8: " .. tostring(utf:error()))
  expect(not tostring(utf:error()):find("\255", 1, true), "no invalid byte in the fault text")
  expect(late:error() == nil, "neighbour still fine at 0.2")
end)
world.at(0.5, function()
  expect(has(strict, "strict_globals.lua:7:"), "strict _G: reading an undefined global faults with file:line: " .. tostring(strict:error()))
  expect(has(late, "still stepping at 0.4"), "neighbour kept stepping: " .. tostring(late:error()))
end)
