-- module.publish / m:published: the world reads what a behaviour published in the step just
-- run, as a fresh copy (changing it changes nothing in the module's record), nil for a key never
-- published or removed, and every key as a table when no key is given.
world.set{gravity = {0, 0, 0}, duration = 0.1}
local m = world.spawn("superbot", {name = "pub", behavior = "../behaviors/publisher.lua"})
local quiet = world.spawn("superbot", {at = {1, 0, 0}, name = "quiet", behavior = "behaviors/hold.lua"})
expect(m:published("step") == nil, "nothing is published before the first step")
world.on_step(function(t)
  local n = math.floor(t / world.dt() + 0.5)
  expect(m:published("step") == n, string.format("step %d: published step %s", n, tostring(m:published("step"))))
  local info = m:published("info")
  expect(info.name == "pub" and info.list[1] == n and info.list[2] == 2 * n and info.flag == (n % 2 == 0),
         "the table came over whole")
  info.list[1] = -1
  expect(m:published("info").list[1] == n, "a copy: changing it changes nothing")
  local all = m:published()
  expect(all.step == n and all.info.name == "pub", "without a key: every key")
  expect((m:published("gone") ~= nil) == (n < 3), string.format("step %d: 'gone' published at 1, removed at 3", n))
  expect(m:published("never") == nil and next(quiet:published()) == nil, "nothing where nothing was published")
end)
