-- Strings that leave little room under the world VM cap, then a table per particle: checked first.
local filler = {} for i = 1, 250 do filler[i] = string.rep("x", 1024 * 1024) end
local p = world.debris{min = {-0.2, -0.2, 0.01}, max = {0.2, 0.2, 0.38}, spacing = 0.01}
local all = p:positions() --!
