-- Host for module-type cases: spawns one module of the type file --param t=PATH (relative to
-- this folder).
world.set{duration = 0.1}
world.ground{}
world.spawn(args.t, {at = {0, 0, 0.3}})
