-- A behaviour with a syntax error and one with a run-time error each fault only their own
-- module, with file:line in the message; the healthy module beside them keeps moving.
world.set{duration = 2, expect_faults = 2}  -- the syntax error and the runtime error
world.ground{}
local syntax = world.spawn("superbot", {at = {0, 0, 0.043}, behavior = "../behaviors/syntax_error.lua"})
local runtime = world.spawn("superbot", {at = {0, 0.5, 0.043}, behavior = "../behaviors/runtime_error.lua"})
local healthy = world.spawn("superbot", {at = {0, 1.0, 0.043}, behavior = "behaviors/sweep.lua"})
world.at(0.1, function()
  local e = syntax:error()
  expect(e ~= nil and e:find("tests/behaviors/syntax_error.lua:4:", 1, true) ~= nil,
         "syntax error names file:line, got: " .. tostring(e))
  expect(runtime:error() == nil, "the run-time error has not happened yet")
end)
world.at(1.5, function()
  local e = runtime:error()
  expect(e ~= nil and e:find("tests/behaviors/runtime_error.lua:7: attempt to index a nil value", 1, true) ~= nil,
         "run-time error names file:line, got: " .. tostring(e))
  expect(e ~= nil and e:find("stack traceback", 1, true) ~= nil, "the fault carries a traceback")
  expect(healthy:error() == nil, "the healthy module did not fault")
  expect(math.abs(healthy:joint_angle("pitch")) > 0.1, "the healthy module keeps moving")
end)
