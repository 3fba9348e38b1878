-- A tiny world for the sweep tests (tests/cli/sweep_test.sh, slurm_sweep.sh): one SuperBot whose
-- joint targets come from --param amp=... and its seeded random stream, for 0.2 s.
world.set{duration = 0.2}
world.ground{friction = 0.8}
world.spawn("superbot", {at = {0, 0, 0.043}, name = "bot", behavior = "wiggle.lua",
                         params = {amp = args.amp or 0.5}})
if args.crash then world.spawn("no_such_type") end
