-- m:published with a key that is not a string
local m = world.spawn("superbot", {at = {0, 0, 0.043}})
print(m:published({}))
