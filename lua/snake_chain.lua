-- A chain of modules docked back to front, spawned already in its travelling wave's pose at
-- t = 0 and lying on the ground: `local snake_chain = require("snake_chain")` in a world script.
--
-- Why: a straight chain that starts a vertical wave must first get shorter, and on a floor with
-- Coulomb friction every module that slides towards the middle pushes with mu m g whatever the
-- speed, so the middle docks carry about mu W / 2 of the chain's weight W (a 150-SuperBot snake
-- at friction 0.8: about 400 N, four times a SuperBot dock's strength). A chain born in the gait's
-- own pose never has to shrink; with `ramp = 0` the behaviour carries on from that pose.
--
--   local chain = snake_chain.build{
--     n = 150, type = "superbot", joint = "pitch",     -- the joint the wave drives
--     amplitude = 0.6, period = 1.5, lag = 2 * math.pi / 5,  -- as behaviors/snake.lua
--     at = {0, 0}, spacing = 0.19, ground = 0,         -- head at (x, y); chain along -x
--     bottom = 0.0430,                                 -- flat: module frame height above the ground
--     behavior = "behaviors/snake.lua", params = {...},  -- each module also gets index, joint,
--                                                      -- amplitude, period, lag and ramp = 0
--     name = "snake_",                                 -- names snake_1 .. snake_n
--     pose = "gait",                                   -- or "flat" (straight, zero angles)
--   }
-- returns the Module handles, head first.
local gaits = require("gaits")
local kin = require("kinematics")

local M = {}

-- Errors name the caller's line (level 3: past check and build).
local function check(ok, what)
  if not ok then error("snake_chain.build: " .. what, 3) end
end

local function finite(v) return type(v) == "number" and v == v and v > -math.huge and v < math.huge end

function M.build(o)
  check(type(o) == "table", "expected a table of options")
  local n = o.n
  check(finite(n) and n >= 1 and n % 1 == 0,
        "n= must be a whole number of modules, 1 or more (got " .. tostring(n) .. ")")
  n = math.tointeger(n)
  local type_name = o.type or "superbot"
  local joint = o.joint or "pitch"
  local amplitude, period = o.amplitude or 0.6, o.period or 1.5
  local lag = o.lag or (2 * math.pi / 5)
  for _, nv in ipairs({ { "amplitude", amplitude }, { "period", period }, { "lag", lag } }) do
    check(finite(nv[2]), nv[1] .. "= must be a finite number (got " .. tostring(nv[2]) .. ")")
  end
  check(period ~= 0, "period= must not be 0")
  local at = o.at or { 0, 0 }
  check(type(at) == "table" and finite(at[1]) and finite(at[2]), "at= must be {x, y} in metres")
  local spacing, ground = o.spacing or 0.19, o.ground or 0
  check(finite(spacing) and finite(ground), "spacing= and ground= must be finite numbers")
  local bottom = o.bottom or 0.0430
  local prefix = o.name or "snake_"
  check(o.pose == nil or o.pose == "gait" or o.pose == "flat", "pose= must be \"gait\" or \"flat\"")
  local gait = (o.pose or "gait") == "gait"
  local tdata = world.module_type(type_name)

  local angles = {}
  for i = 1, n do angles[i] = gait and gaits.wave(0, i - 1, amplitude, period, lag) or 0 end

  -- Poses from the kinematic model (the head's module frame at the origin, a metre up); once
  -- docked, world.place_on_ground lowers the chain until its lowest point touches the ground.
  local poses = {}
  if gait then
    local mods, conns = {}, {}
    for i = 1, n do
      mods[i] = { name = prefix .. i, type = tdata }
      if i > 1 then conns[#conns + 1] = { prefix .. (i - 1), "back", prefix .. i, "front", 0 } end
    end
    local byName = {}
    for i = 1, n do byName[prefix .. i] = { [joint] = angles[i] } end
    local s = kin.structure{ modules = mods, connections = conns, base = prefix .. 1 }
    local q = s:angles_from(byName)
    local f = s:fk(q)
    -- The joints' partial sums of a wave do not average to zero, so a chain whose head is level
    -- climbs. Turn the whole chain so that it rests: the edge of its profile's lower convex hull
    -- under its centre of mass becomes level (for a periodic wave, the line through its troughs),
    -- so every trough touches the ground together and no end is left to fall.
    local h, t = f:link(prefix .. 1, tdata.root), f:link(prefix .. n, tdata.root)
    local d = { t[1] - h[1], t[2] - h[2] }
    local flat = math.sqrt(d[1] ^ 2 + d[2] ^ 2)
    if n > 1 and flat > 0 then
      local pts, mean = {}, 0
      for i = 1, n do
        local p = f:link(prefix .. i, tdata.root)
        pts[i] = { s = ((p[1] - h[1]) * d[1] + (p[2] - h[2]) * d[2]) / flat, p = p }
        mean = mean + pts[i].s / n
      end
      table.sort(pts, function(a, b) return a.s < b.s end)
      local hull = {}
      for _, pt in ipairs(pts) do  -- the lower hull, left to right (monotone chain)
        while #hull >= 2 do
          local a, b = hull[#hull - 1], hull[#hull]
          if (b.s - a.s) * (pt.p[3] - a.p[3]) - (b.p[3] - a.p[3]) * (pt.s - a.s) > 0 then break end
          hull[#hull] = nil
        end
        hull[#hull + 1] = pt
      end
      local a, b = hull[1], hull[#hull]
      for k = 1, #hull - 1 do
        if hull[k].s <= mean and mean <= hull[k + 1].s then a, b = hull[k], hull[k + 1] break end
      end
      local e = { b.p[1] - a.p[1], b.p[2] - a.p[2], b.p[3] - a.p[3] }
      local ef = math.sqrt(e[1] ^ 2 + e[2] ^ 2)
      -- the turn from e to its level projection: about e x up's direction, by its climb angle
      local ax = { e[2], -e[1], 0 }  -- e x (0, 0, 1), horizontal, normal to e
      local an = math.sqrt(ax[1] ^ 2 + ax[2] ^ 2)
      local angle = ef > 0 and -math.atan(e[3], ef) or 0
      if an > 0 and angle ~= 0 then
        local c, sn = math.cos(angle / 2), math.sin(angle / 2) / an
        s = kin.structure{ modules = mods, connections = conns, base = prefix .. 1,
                           base_pose = { at = { 0, 0, 0 }, quat = { c, ax[1] * sn, ax[2] * sn, 0 } } }
        f = s:fk(q)
      end
    end
    for i = 1, n do
      local p, rot = f:link_pose(prefix .. i, tdata.root)
      poses[i] = { at = { at[1] + p[1], at[2] + p[2], ground + 1 + p[3] }, quat = rot }
    end
  else
    for i = 1, n do poses[i] = { at = { at[1] - (i - 1) * spacing, at[2], ground + bottom } } end
  end

  local chain = {}
  for i = 1, n do
    local params = {}
    for k, v in pairs(o.params or {}) do params[k] = v end
    params.index, params.joint, params.amplitude, params.period, params.lag = i - 1, joint, amplitude, period, lag
    if gait then params.ramp = 0 end
    chain[i] = world.spawn(type_name, {
      at = poses[i].at, quat = poses[i].quat, name = prefix .. i, behavior = o.behavior, params = params,
      joints = { [joint] = angles[i] },
    })
    if i > 1 then world.connect(chain[i - 1], "back", chain[i], "front") end
  end
  if gait then world.place_on_ground(chain[1], ground) end
  return chain
end

return M
