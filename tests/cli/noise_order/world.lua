-- One SuperBot acting through noisy actions in the order --param order=forward|reverse|pairs
-- (tests/cli/cli_tests.cmake compares the runs: they must end bit for bit alike).
world.set{duration = 0.5, seed = 7}
world.ground{}
world.spawn("superbot", {at = {0, 0, 0.043}, name = "bot", behavior = "act_order.lua",
                         params = {order = args.order or "forward"}})
