-- Checks what a behaviour can reach (for sandbox.lua); errors out if it sees too much.
assert(io == nil and os == nil and dofile == nil and loadfile == nil and package == nil, "unsafe library visible")
assert(not pcall(require, "../secrets"), "require escaped the Lua folders")
assert(load(string.dump(function() end)) == nil, "binary chunk accepted")
local helper = require("probe_helper")
assert(helper.answer == 42, "require found the script's folder")
function step(dt) end
