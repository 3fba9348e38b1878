-- Fork test world (tests/cli/replay_test.sh): two SuperBots; each holds its pitch joint at the
-- angle its behaviour (target.lua, beside this file) sets. The test edits the behaviour in a copy
-- of this folder and forks a recording of this world at t = 1 s.
world.set{dt = 1 / 60, duration = 2}
world.ground{}
world.box{size = {0.1, 0.1, 0.1}, at = {0.4, 0.3, 0.05}}
for i = 1, 2 do
  world.spawn("superbot", {at = {0, (i - 1) * 0.2, 0.043}, name = "bot" .. i, behavior = "target.lua"})
end
