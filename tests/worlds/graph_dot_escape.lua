-- DOT export with awkward module names: quotes, backslashes and line breaks in a name are escaped,
-- so every label is one well-formed quoted string (world.graph("dot"), run --graph FILE.dot).
world.set{duration = 0.05}
world.ground{}
local a = world.spawn("superbot", {at = {0, 0, 0.043}, name = 'say "hi"'})
local b = world.spawn("superbot", {name = "back\\slash\nand a line"})
world.connect(a, "back", b, "front")

-- Scans a DOT statement: returns the quoted strings' contents (escapes kept) and the text outside
-- them, or nil and why when a string is not closed on its line.
local function scan(line)
  local strings, outside, i = {}, {}, 1
  while i <= #line do
    local c = line:sub(i, i)
    if c == '"' then
      local j, s = i + 1, {}
      while true do
        local d = line:sub(j, j)
        if d == "" then return nil, "unterminated string in: " .. line end
        if d == "\\" then
          s[#s + 1] = line:sub(j, j + 1)
          j = j + 2
        elseif d == '"' then
          break
        else
          s[#s + 1] = d
          j = j + 1
        end
      end
      strings[#strings + 1] = table.concat(s)
      outside[#outside + 1] = "S"
      i = j + 1
    else
      outside[#outside + 1] = c
      i = i + 1
    end
  end
  return strings, table.concat(outside)
end

world.on_end(function()
  local dot = world.graph("dot")
  local labels, shapes = {}, {}
  for line in dot:gmatch("[^\n]+") do
    local strings, shape = scan(line)
    expect(strings ~= nil, shape)
    if strings then
      shapes[#shapes + 1] = shape
      for _, s in ipairs(strings) do labels[#labels + 1] = s end
    end
  end
  expect(table.concat(shapes, "|") ==
         "graph rm3d {|  node [shape=box];|  m1 [label=S];|  m2 [label=S];|  m1 -- m2 [taillabel=S, headlabel=S];|}",
         "DOT statements as expected, got:\n" .. dot)
  expect(labels[1] == 'say \\"hi\\"\\nsuperbot', "quotes escaped: " .. tostring(labels[1]))
  expect(labels[2] == "back\\\\slash\\nand a line\\nsuperbot", "backslash and line break escaped: " .. tostring(labels[2]))
  expect(labels[3] == "back" and labels[4] == "front", "dock labels")
end)
