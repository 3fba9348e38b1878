local j = module.joint('pitch')
local d = module.dock('front')
g = setmetatable({}, {__gc = function() j:set_target(1); d:enable(); log(module.receive(), sim.time()) end})
function step(dt) end
