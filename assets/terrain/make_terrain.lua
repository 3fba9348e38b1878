-- Generates the heightfield images (grayscale PNG, black = lowest, white = highest) that
-- world.heightfield reads, and the small images the terrain tests use:
--   assets/terrain/hills_30.png      30 x 30 pixels: rolling hills, a ridge and a hollow, like the
--                                    30 x 30 terrain of the ReMod3D paper's Fig. 1(g)
--                                    (worlds/terrain.lua)
--   assets/terrain/hills_256.png     256 x 256 pixels: the same landscape, finer, with small
--                                    bumps added (a larger terrain for one's own worlds)
--   tests/worlds/terrain_steps.png   30 x 30: three flat terraces (gray 0, 128 and 255) joined by
--                                    ramps (tests/worlds/terrain.lua)
--   tests/bad_inputs/world/heightfield_colour.png  4 x 4 with coloured pixels (rejected)
--   tests/bad_inputs/world/heightfield_1px.png     1 x 1 (too small for a grid)
-- Plain Lua 5.4, no libraries: the PNG files hold uncompressed ("stored") deflate blocks, which
-- every PNG reader accepts. Deterministic: running it again gives the same bytes.
-- Run from the project root, then commit the images:
--   lua5.4 assets/terrain/make_terrain.lua

-- ---- PNG writer

local crcTable = {}
for n = 0, 255 do
  local c = n
  for _ = 1, 8 do c = (c & 1) ~= 0 and (0xEDB88320 ~ (c >> 1)) or (c >> 1) end
  crcTable[n] = c
end

local function crc32(s)
  local c = 0xFFFFFFFF
  for i = 1, #s do c = crcTable[(c ~ s:byte(i)) & 0xFF] ~ (c >> 8) end
  return c ~ 0xFFFFFFFF
end

local function adler32(s)
  local a, b = 1, 0
  for i = 1, #s do
    a = (a + s:byte(i)) % 65521
    b = (b + a) % 65521
  end
  return (b << 16) | a
end

local function chunk(kind, data)
  return string.pack(">I4", #data) .. kind .. data .. string.pack(">I4", crc32(kind .. data))
end

--- Writes a PNG: `pixel(x, y)` gives the gray value 0..255 (or {r, g, b} when `colour`) of
--- column x, row y (0-based, row 0 at the top of the picture).
local function writePng(path, width, height, pixel, colour)
  local rows = {}
  for y = 0, height - 1 do
    local row = {"\0"}  -- filter type 0 (none)
    for x = 0, width - 1 do
      local v = pixel(x, y)
      row[#row + 1] = colour and string.char(v[1], v[2], v[3]) or string.char(v)
    end
    rows[#rows + 1] = table.concat(row)
  end
  local raw = table.concat(rows)
  local blocks, at = {"\x78\x01"}, 1
  repeat  -- stored deflate blocks of at most 65535 bytes
    local part = raw:sub(at, at + 65534)
    at = at + #part
    local final = at > #raw and 1 or 0
    blocks[#blocks + 1] = string.pack("<I1I2I2", final, #part, (~#part) & 0xFFFF) .. part
  until at > #raw
  blocks[#blocks + 1] = string.pack(">I4", adler32(raw))
  local png = "\x89PNG\r\n\x1a\n" ..
      chunk("IHDR", string.pack(">I4I4I1I1I1I1I1", width, height, 8, colour and 2 or 0, 0, 0, 0)) ..
      chunk("IDAT", table.concat(blocks)) .. chunk("IEND", "")
  local f = assert(io.open(path, "wb"))
  f:write(png)
  f:close()
  print(string.format("wrote %s (%d x %d)", path, width, height))
end

-- ---- landscapes

local function clamp(v, lo, hi) return math.max(lo, math.min(hi, v)) end
local function bump(u, v, cu, cv, radius) return math.exp(-((u - cu) ^ 2 + (v - cv) ^ 2) / (radius * radius)) end

--- The landscape at (u, v) in [0, 1]^2 (u to the right, v down the picture), 0..1.
local function hills(u, v, detail)
  local h = 0.30
  h = h + 0.55 * bump(u, v, 0.25, 0.30, 0.18)          -- a round hill
  h = h + 0.40 * bump(u, v, 0.72, 0.22, 0.14)          -- a smaller one
  h = h + 0.35 * bump(u, v, 0.60, 0.75, 0.22)          -- a broad rise
  h = h - 0.28 * bump(u, v, 0.30, 0.78, 0.13)          -- a hollow
  h = h + 0.18 * math.exp(-((u - 0.45 - 0.3 * (v - 0.5)) / 0.06) ^ 2) * (1 - bump(u, v, 0.5, 0.5, 0.2))  -- a ridge
  h = h + 0.05 * math.sin(7 * u + 2) * math.cos(5 * v)  -- gentle undulation
  if detail then h = h + 0.03 * math.sin(61 * u) * math.sin(53 * v + 1) end
  return clamp(h, 0, 1)
end

local function sample(size, detail)
  return function(x, y)
    return math.floor(hills(x / (size - 1), y / (size - 1), detail) * 255 + 0.5)
  end
end

writePng("assets/terrain/hills_30.png", 30, 30, sample(30, false))
writePng("assets/terrain/hills_256.png", 256, 256, sample(256, true))

-- Terraces across x: columns 0-7 gray 0, 12-17 gray 128, 22-29 gray 255, ramps between.
writePng("tests/worlds/terrain_steps.png", 30, 30, function(x)
  if x <= 7 then return 0 end
  if x < 12 then return math.floor(128 * (x - 7) / 5 + 0.5) end
  if x <= 17 then return 128 end
  if x < 22 then return math.floor(128 + 127 * (x - 17) / 5 + 0.5) end
  return 255
end)

writePng("tests/bad_inputs/world/heightfield_colour.png", 4, 4, function(x, y)
  return (x + y) % 2 == 0 and {200, 40, 40} or {40, 40, 200}
end, true)
writePng("tests/bad_inputs/world/heightfield_1px.png", 1, 1, function() return 128 end)
