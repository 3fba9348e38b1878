-- Generates the ATRON hemisphere mesh (a closed convex OBJ file, triangles wound
-- counter-clockwise seen from outside, in metres) used by assets/modules/atron.lua:
--   atron_hemisphere.obj  a hemisphere of radius 0.055: the flat face on z = 0, the dome towards
--                         +z; 8 rings of 24 points at elevations 0, 11.25, ..., 78.75 degrees plus
--                         the pole (193 points). Every 45 degrees of elevation and 90 degrees of
--                         azimuth lies on a ring point, so the four connector centres of an ATRON
--                         hemisphere (elevation 45 degrees, azimuths 0, 90, 180, 270) are mesh
--                         points exactly on the sphere.
--   atron_hemisphere_collision.obj  the same dome with 77 points (24, 24, 16, 12 a ring): what the
--                         hemispheres collide as.
-- The north hemisphere uses them as they are, the south one turned 180 degrees about x.
-- Run from the project root with the plain interpreter, then commit the OBJ file:
--   lua5.4 assets/meshes/make_atron_meshes.lua

local kOutDir = "assets/meshes/"
local kRadius = 0.055
local kRings = 8       -- rings from the equator (ring 0, z = 0) up to just below the pole
local kSegments = 24   -- points per ring

local obj = require("assets.meshes.obj_writer")  -- run from the project root
local newMesh, addPoint = obj.newMesh, obj.addPoint
local function writeObj(name, mesh, what) obj.write(kOutDir, name, mesh, what, "assets/meshes/make_atron_meshes.lua") end

-- Hemisphere: ring k (0..rings-1) at elevation k * 90 / rings degrees (or elevations[k + 1]
-- degrees), then the pole; ring k has segments[k + 1] points (or `segments` points on every ring
-- when it is a number).
local function hemisphere(r, rings, segments, elevations)
  local function count(k) return type(segments) == "table" and segments[k + 1] or segments end
  local mesh = { points = {}, faces = {} }
  local ring = {}
  for k = 0, rings - 1 do
    local el = elevations and math.rad(elevations[k + 1]) or (math.pi / 2) * k / rings
    ring[k] = {}
    for s = 0, count(k) - 1 do
      local az = 2 * math.pi * s / count(k)
      mesh.points[#mesh.points + 1] = { r * math.cos(el) * math.cos(az), r * math.cos(el) * math.sin(az),
                                        k == 0 and 0 or r * math.sin(el) }
      ring[k][s] = #mesh.points
    end
  end
  mesh.points[#mesh.points + 1] = { 0, 0, r }
  local pole = #mesh.points
  -- The flat face on z = 0.
  local base = {}
  for s = 0, count(0) - 1 do base[#base + 1] = ring[0][s] end
  mesh.faces[#mesh.faces + 1] = base
  -- Quads between rings of equal counts; between unequal ones, triangles zipped in azimuth order.
  for k = 0, rings - 2 do
    local na, nb = count(k), count(k + 1)
    if na == nb then
      for s = 0, na - 1 do
        local t = (s + 1) % na
        mesh.faces[#mesh.faces + 1] = { ring[k][s], ring[k][t], ring[k + 1][t], ring[k + 1][s] }
      end
    else
      local i, j = 0, 0
      while i < na or j < nb do
        if j >= nb or (i < na and (i + 1) / na <= (j + 1) / nb) then
          mesh.faces[#mesh.faces + 1] = { ring[k][i % na], ring[k][(i + 1) % na], ring[k + 1][j % nb] }
          i = i + 1
        else
          mesh.faces[#mesh.faces + 1] = { ring[k][i % na], ring[k + 1][(j + 1) % nb], ring[k + 1][j % nb] }
          j = j + 1
        end
      end
    end
  end
  local top = count(rings - 1)
  for s = 0, top - 1 do
    mesh.faces[#mesh.faces + 1] = { ring[rings - 1][s], ring[rings - 1][(s + 1) % top], pole }
  end
  return mesh
end

writeObj("atron_hemisphere.obj", hemisphere(kRadius, kRings, kSegments),
         "ATRON hemisphere, radius 0.055, flat face on z = 0, dome towards +z")
-- The collision hull: rings at 0, 11.25, 33.75 and 56.25 degrees of 24, 24, 16 and 12 points,
-- plus the pole (77 points). The equator and the ring above it are the drawn mesh's, so an ATRON
-- rolling on its equator meets the ground on the same rounded rim and rolls as far (with only the
-- equator ring at the rim, it balanced on the seam's edge and rolled 38% less at 2 substeps); the
-- facets above lie up to 2.5 mm inside the sphere (the drawn mesh's, 0.7 mm), and Bullet's support
-- search over the hull costs about 40% of the 193-point one's.
writeObj("atron_hemisphere_collision.obj", hemisphere(kRadius, 4, { 24, 24, 16, 12 }, { 0, 11.25, 33.75, 56.25 }),
         "ATRON hemisphere collision hull, radius 0.055, 77 points")
