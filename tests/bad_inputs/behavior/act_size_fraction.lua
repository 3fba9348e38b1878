-- act_size must be a whole number: 1.5 is not rounded down.
act_size = 1.5
function step() end
