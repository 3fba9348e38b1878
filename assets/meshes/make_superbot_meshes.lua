-- Generates the SuperBot U-bracket meshes (closed convex OBJ files, triangles wound
-- counter-clockwise seen from outside, in metres) used by assets/modules/superbot.lua:
--   superbot_end_plate.obj   the end plate: 0.012 (x) by 0.084 by 0.084 box, centred on its
--                            origin, every edge chamfered by 0.004 (24 points)
--   superbot_side_plate.obj  a side plate shaped like a "D": 0.012 thick in y around y = 0; in
--                            the xz plane the rectangle x in [0, 0.052], z in [-0.042, 0.042] plus
--                            a half disc of radius 0.042 about the origin for x < 0 (16 segments),
--                            so the origin is the hinge pivot (38 points)
--   superbot_bracket_hull.obj the convex hull of a whole bracket (end plate and both side
--                            plates): the same D profile, 0.084 wide in y (38 points); the
--                            bracket's collision geometry, one hull instead of three
-- Run from the project root with the plain interpreter, then commit the OBJ files:
--   lua5.4 assets/meshes/make_superbot_meshes.lua

local kOutDir = "assets/meshes/"

-- Vector helpers on {x, y, z} arrays.
local obj = require("assets.meshes.obj_writer")  -- run from the project root
local newMesh, addPoint = obj.newMesh, obj.addPoint
local function writeObj(name, mesh, what) obj.write(kOutDir, name, mesh, what, "assets/meshes/make_superbot_meshes.lua") end

-- End plate: a box with half extents h, every edge cut at 45 degrees by c. Each corner of the box
-- becomes a small triangle of three points, one on each of the three faces meeting there.
local function endPlate(hx, hy, hz, c)
  local mesh = newMesh()
  local h = { hx, hy, hz }
  -- corner[sx][sy][sz][axis]: the point of that corner lying on the face normal to `axis`.
  local corner = {}
  for _, sx in ipairs({ -1, 1 }) do
    corner[sx] = {}
    for _, sy in ipairs({ -1, 1 }) do
      corner[sx][sy] = {}
      for _, sz in ipairs({ -1, 1 }) do
        local s = { sx, sy, sz }
        local pts = {}
        for axis = 1, 3 do
          local p = {}
          for k = 1, 3 do p[k] = s[k] * (k == axis and h[k] or h[k] - c) end
          pts[axis] = addPoint(mesh, p)
        end
        corner[sx][sy][sz] = pts
        mesh.faces[#mesh.faces + 1] = { pts[1], pts[2], pts[3] }  -- corner triangle
      end
    end
  end
  local function at(s, axis) return corner[s[1]][s[2]][s[3]][axis] end
  -- The six main faces: the four corner points lying on each face, in cyclic order.
  for axis = 1, 3 do
    local u, v = axis % 3 + 1, (axis + 1) % 3 + 1
    for _, sa in ipairs({ -1, 1 }) do
      local face = {}
      for _, uv in ipairs({ { -1, -1 }, { 1, -1 }, { 1, 1 }, { -1, 1 } }) do
        local s = {}
        s[axis], s[u], s[v] = sa, uv[1], uv[2]
        face[#face + 1] = at(s, axis)
      end
      mesh.faces[#mesh.faces + 1] = face
    end
  end
  -- The twelve chamfers: along the edge parallel to `axis` where faces u and v meet.
  for axis = 1, 3 do
    local u, v = axis % 3 + 1, (axis + 1) % 3 + 1
    for _, su in ipairs({ -1, 1 }) do
      for _, sv in ipairs({ -1, 1 }) do
        local lo, hi = {}, {}
        lo[axis], lo[u], lo[v] = -1, su, sv
        hi[axis], hi[u], hi[v] = 1, su, sv
        mesh.faces[#mesh.faces + 1] = { at(lo, u), at(hi, u), at(hi, v), at(lo, v) }
      end
    end
  end
  return mesh
end

-- Side plate: the D-shaped profile in the xz plane, extruded from y = -hy to y = +hy.
local function sidePlate(length, r, hy, segments)
  local profile = { { length, -r }, { length, r } }
  for i = 0, segments do
    local a = math.pi / 2 + math.pi * i / segments  -- from +z over -x to -z
    profile[#profile + 1] = { r * math.cos(a), r * math.sin(a) }
  end
  local mesh = newMesh()
  local top, bottom = {}, {}
  for i, q in ipairs(profile) do
    top[i] = addPoint(mesh, { q[1], hy, q[2] })
    bottom[i] = addPoint(mesh, { q[1], -hy, q[2] })
  end
  mesh.faces[#mesh.faces + 1] = top
  mesh.faces[#mesh.faces + 1] = bottom
  for i = 1, #profile do
    local j = i % #profile + 1
    mesh.faces[#mesh.faces + 1] = { top[i], top[j], bottom[j], bottom[i] }
  end
  return mesh
end

writeObj("superbot_end_plate.obj", endPlate(0.006, 0.042, 0.042, 0.004),
         "SuperBot bracket end plate, 0.012 x 0.084 x 0.084, chamfer 0.004, centred")
writeObj("superbot_side_plate.obj", sidePlate(0.052, 0.042, 0.006, 16),
         "SuperBot bracket side plate, D-shaped, 0.012 thick in y, hinge pivot at the origin")
writeObj("superbot_bracket_hull.obj", sidePlate(0.052, 0.042, 0.042, 16),
         "SuperBot bracket convex hull (collision), D-shaped, 0.084 wide in y, hinge pivot at the origin")
