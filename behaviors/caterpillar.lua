-- Caterpillar gait (ReMod3D's): no module is told where it is in the chain. The head (the
-- module with nothing docked at its front) starts with counter 0 and sends 1 down its back
-- dock; every other module takes the counter it receives on its front dock as its place in the
-- chain, sets its phase from it, and forwards counter + 1. The wave then runs like snake.lua's.
-- params: joint ("pitch"), amplitude (0.6 rad), period (1.5 s), lag (2*pi/5 rad per module)
local gaits = require("gaits")
local joint = module.joint(params.joint or "pitch")
local amplitude = params.amplitude or 0.6
local period = params.period or 1.5
local lag = params.lag or (2 * math.pi / 5)
local front, back = module.dock("front"), module.dock("back")

function step(dt)
  if state.counter == nil then
    if not front:engaged() then
      state.counter = 0
      back:send(1)
    else
      local msg = module.receive("front")
      if msg then
        state.counter = msg.data
        back:send(msg.data + 1)  -- false at the tail: nothing engaged there
      end
    end
  end
  while module.receive() do end  -- anything else is not for us
  if state.counter then joint:set_target(gaits.wave(sim.time(), state.counter, amplitude, period, lag)) end
end
