-- Unknown joint names and wrong argument types in a behaviour fault that module with a message
-- naming file:line and what was expected; world-side mistakes raise errors the script can catch.
world.set{duration = 0.2}
local a = world.spawn("superbot", {behavior = "../behaviors/bad_joint_name.lua"})
local b = world.spawn("superbot", {at = {1, 0, 0}, behavior = "../behaviors/bad_argument.lua"})
world.at(0.1, function()
  local ea, eb = tostring(a:error()), tostring(b:error())
  expect(ea:find("bad_joint_name.lua:2: module.joint: no joint named 'elbow' on a superbot (it has: pitch, roll, yaw)", 1, true),
         "unknown joint: " .. ea)
  expect(eb:find("bad_argument.lua:4: bad argument #1 to 'set_target' (number expected, got string)", 1, true),
         "wrong type: " .. eb)
end)
local ok, err = pcall(function() return a:joint_angle("knee") end)
expect(not ok and err:find("no joint named 'knee'", 1, true), "world side: " .. tostring(err))
ok, err = pcall(world.box, {size = {1, 1}})
expect(not ok and err:find("option 'size' must be a table of 3 numbers", 1, true), "box size: " .. tostring(err))
ok, err = pcall(world.spawn, "superbot", {params = 5})
expect(not ok and err:find("option 'params' must be a table", 1, true), "params: " .. tostring(err))
