-- Noise models (lua/noise.lua) and percept/action declarations on a Wheelbot:
--   * statistics and exact behaviour of every model, checked from inside a behaviour with a fixed
--     seed (tests/behaviors/noise_stats.lua: gaussian, uniform, bias, offset, drift, wander, dropout, quantise,
--     saturate, delay, stuck, compose, and lists of models in percepts and actions); it errors on
--     any failed check and disables its "back" dock when all of them ran;
--   * bad declarations fail at load, each with the behaviour's file and the declaring line: a
--     negative sigma, a dropout probability outside [0, 1], a non-number sigma, a percept naming a
--     sensor the Wheelbot lacks, an action on a joint it lacks.
world.set{duration = 2.5, seed = 7, expect_faults = 5}  -- the five misconfigured noise modules
world.ground{}

local stats = world.spawn("wheelbot", {name = "stats", at = {0, 0, 0.041}, behavior = "../behaviors/noise_stats.lua"})

local bad = {
  {file = "noise_bad_sigma.lua", line = 4, text = "noise.gaussian: sigma must not be negative, got -1"},
  {file = "noise_bad_dropout.lua", line = 4, text = "noise.dropout: p must be in [0, 1], got 1.5"},
  {file = "noise_bad_type.lua", line = 4, text = "noise.gaussian: sigma must be a number, got string"},
  {file = "percept_bad_sensor.lua", line = 5, text = "percepts.tilt: no sensor 'accelerometr' on a wheelbot"},
  {file = "action_bad_joint.lua", line = 5, text = "actions.middle: no joint 'wheel_ml' on a wheelbot"},
}
for i, b in ipairs(bad) do
  b.m = world.spawn("wheelbot", {name = b.file:gsub("%.lua$", ""), at = {0, i * 0.5, 0.041},
                                 behavior = "../behaviors/" .. b.file})
end

world.at(0.1, function()
  for _, b in ipairs(bad) do
    local e = tostring(b.m:error())
    local head = e:match("^[^\n]*")
    local want = string.format("tests/behaviors/%s:%d: %s", b.file, b.line, b.text)
    expect(head:find(want, 1, true) == 1, string.format("%s should fail at load with\n  %s\ngot\n  %s", b.file, want, head))
  end
end)

world.at(2.5, function()
  expect(stats:error() == nil, "the noise statistics: " .. tostring(stats:error()))
  expect(stats:dock_state("back").enabled == false, "the noise statistics ran to the end (back dock disabled)")
end)
