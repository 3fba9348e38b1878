-- Two module types in one world (tests/python): a SuperBot (3 joints, 6 docks) and a Wheelbot.
world.set{dt = 1 / 60, duration = 5, seed = 2}
world.ground{friction = 0.8}
world.spawn("superbot", {at = {0, 0, 0.06}})
if (args.wheelbots or 1) > 0 then
  for i = 1, args.wheelbots or 1 do world.spawn("wheelbot", {at = {0.5 * i, 1, 0.041}}) end
end
