-- Turns off the motors of the joints named in params.free (joint:free()); every other joint keeps
-- the default servo at 0. Used by the analytic tests.
local free = {}
for _, name in ipairs(params.free or {}) do free[#free + 1] = module.joint(name) end

function step(dt)
  for i = 1, #free do free[i]:free() end
end
