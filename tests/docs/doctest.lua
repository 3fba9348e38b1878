-- The documentation's commands run, and the outputs it shows are the ones they print.
--
-- In README.md and docs/**/*.md, a fenced block opened with "```sh doctest" holds commands, one a
-- line (a trailing \ continues it); they run in order, in one scratch folder per page that holds
-- links to the checkout's assets/, behaviors/, lua/ and worlds/ (so it looks like the checkout to
-- the commands, which write their outputs there), with the rm3d under test first on PATH and its
-- Python package (BUILD/python) on PYTHONPATH. Each must exit 0 (or N, given as "```sh doctest exit=N"). When the next
-- block (after blank lines only) opens with "```text output", the commands' output (stdout and
-- stderr together) must be that text once normalised: wall-clock times and speeds, the version
-- and the scratch folder are replaced by placeholders. --update writes the real outputs into the
-- pages instead of comparing (after a change that moves the figures: run it, read the diff,
-- commit). "```sh doctest picture=OUT:SHOWN" also checks the picture SHOWN (in the repository)
-- against the file OUT the commands wrote (--update copies OUT to SHOWN).
-- Usage: lua5.4 tests/docs/doctest.lua RM3D SRC SCRATCH [--update]
local rm3d, src, scratch, mode = arg[1], arg[2], arg[3], arg[4]
if not (rm3d and src and scratch) or (mode and mode ~= "--update") then
  io.stderr:write("usage: lua5.4 tests/docs/doctest.lua RM3D SRC SCRATCH [--update]\n")
  os.exit(2)
end
local update = mode == "--update"

local function shellQuote(s)
  return "'" .. s:gsub("'", "'\\''") .. "'"
end

local function run(cmd)
  local p = io.popen(cmd, "r")
  local out = p:read("a")
  local ok, how, code = p:close()
  return out, (how == "exit" and code or 128 + (code or 0))
end

local function absolute(path)
  local out = run("readlink -f " .. shellQuote(path))
  return (out:gsub("\n$", ""))
end
rm3d, src = absolute(rm3d), absolute(src)
local binDir = rm3d:match("^(.*)/[^/]*$")
run("mkdir -p " .. shellQuote(scratch))
scratch = absolute(scratch)

local pages = {}
do
  local list = run("cd " .. shellQuote(src) .. " && { echo README.md; find docs -name '*.md' | sort; }")
  for line in list:gmatch("[^\n]+") do pages[#pages + 1] = line end
end

-- Normalised text: what may differ between runs of the same command on the same build.
local function normalise(text, dir)
  text = text:gsub(dir:gsub("%p", "%%%0"), "<DIR>")
  text = text:gsub(src:gsub("%p", "%%%0"), "<SRC>")
  text = text:gsub("simulated in [%d%.]+ s %([%d%.]+x real time%)", "simulated in <T> s (<R>x real time)")
  text = text:gsub("rm3d %d+%.%d+%.%d+[%w%+%-%.]*", "rm3d <VERSION>")
  text = text:gsub('"wall_seconds": [%d%.e%-]+', '"wall_seconds": <T>')
  text = text:gsub('"version": "[^"]*"', '"version": "<VERSION>"')
  text = text:gsub("simulated, [%d%.]+ s%)", "simulated, <T> s)")
  text = text:gsub("[%d%.]+ ms per step", "<MS> ms per step")
  text = text:gsub("\n+$", "")
  return text
end

-- Reads a page into blocks: {kind = "sh" | "out" | nil, first = line, last = line, text = ...}.
local function blocks(lines)
  local list, i = {}, 1
  while i <= #lines do
    local info = lines[i]:match("^```(.*)$")
    if info then
      local j = i + 1
      while j <= #lines and not lines[j]:match("^```%s*$") do j = j + 1 end
      local body = {}
      for k = i + 1, j - 1 do body[#body + 1] = lines[k] end
      list[#list + 1] = {info = info, first = i, last = j, body = body}
      i = j + 1
    else
      i = i + 1
    end
  end
  return list
end

local failures, commands, outputs, changed = 0, 0, 0, 0
for _, page in ipairs(pages) do
  local path = src .. "/" .. page
  local lines = {}
  for l in io.lines(path) do lines[#lines + 1] = l end
  local bs = blocks(lines)
  local dir = scratch .. "/" .. page:gsub("[/%.]", "_")
  -- A project folder like the checkout: the shipped data copied in (not linked: the path rule
  -- follows links and refuses files outside the project, docs/limits.md), outputs written here.
  run("rm -rf " .. shellQuote(dir) .. " && mkdir -p " .. shellQuote(dir))
  for _, d in ipairs({"assets", "behaviors", "lua", "worlds"}) do
    run("cp -R " .. shellQuote(src .. "/" .. d) .. " " .. shellQuote(dir .. "/" .. d))
  end
  local replacements = {}
  for n, b in ipairs(bs) do
    local expectCode = b.info:match("^sh doctest exit=(%d+)%s*$")
    local drawn, shownPicture = b.info:match("^sh doctest picture=([^:%s]+):(%S+)%s*$")
    if b.info:match("^sh doctest%s*$") or expectCode or drawn then
      local cmds, cur = {}, ""
      for _, l in ipairs(b.body) do
        if l:match("\\%s*$") then
          cur = cur .. l:gsub("\\%s*$", "") .. " "
        else
          cmds[#cmds + 1] = cur .. l
          cur = ""
        end
      end
      local output = {}
      for _, c in ipairs(cmds) do
        if not c:match("^%s*$") and not c:match("^%s*#") then
          commands = commands + 1
          local full = "cd " .. shellQuote(dir) .. " && PATH=" .. shellQuote(binDir) .. ":\"$PATH\" " ..
                       "PYTHONPATH=" .. shellQuote(binDir .. "/python") .. " RM3D_BIN=" .. shellQuote(rm3d) .. " " ..
                       "RM3D_DOC_SRC=" .. shellQuote(src) .. " timeout 600 bash -c " .. shellQuote(c) .. " 2>&1"
          local out, code = run(full)
          output[#output + 1] = out
          local want = tonumber(expectCode or "0")
          if code ~= want then
            failures = failures + 1
            print(string.format("FAIL %s:%d: `%s` exited %d (expected %d):\n%s", page, b.first, c, code, want,
                                out:sub(-2000)))
          else
            print(string.format("ok   %s:%d: %s", page, b.first, c))
          end
        end
      end
      -- A picture the docs show, drawn by these commands: --update copies it in; otherwise the one
      -- in the repository must look the same (tests/tools/image_compare.cpp `same`: the same size,
      -- pixels equal to a rounding), so it cannot go stale.
      if drawn then
        local made, shown = dir .. "/" .. drawn, src .. "/" .. shownPicture
        if update then
          run("cp " .. shellQuote(made) .. " " .. shellQuote(shown))
          print(string.format("ok   %s:%d: wrote %s from %s", page, b.first, shownPicture, drawn))
        else
          local out, code = run(shellQuote(binDir .. "/rm3d_image_compare") .. " same " .. shellQuote(shown) ..
                                " " .. shellQuote(made) .. " 2>&1")
          if code ~= 0 then
            failures = failures + 1
            print(string.format("FAIL %s:%d: the picture %s is not what the commands draw (%s); "
                                .. "tests/docs/doctest.lua --update redraws it", page, b.first, shownPicture,
                                out:gsub("\n$", "")))
          else
            print(string.format("ok   %s:%d: %s is what the commands draw", page, b.first, shownPicture))
          end
        end
      end
      -- The shown output, if any: the next block, with only blank lines between.
      local nb = bs[n + 1]
      if nb and nb.info:match("^text output%s*$") then
        local between = true
        for k = b.last + 1, nb.first - 1 do
          if not lines[k]:match("^%s*$") then between = false end
        end
        if between then
          outputs = outputs + 1
          local real = table.concat(output)
          local shown = table.concat(nb.body, "\n")
          if update then
            local text = real:gsub(dir:gsub("%p", "%%%0"), "."):gsub("\n+$", "")
            if normalise(shown, dir) ~= normalise(text, dir) then
              replacements[#replacements + 1] = {nb.first, nb.last, text}
            end
          elseif normalise(shown, dir) ~= normalise(real:gsub(dir:gsub("%p", "%%%0"), "."), dir) then
            failures = failures + 1
            print(string.format("FAIL %s:%d: the output shown differs from the real one\n--- shown\n%s\n--- real\n%s",
                                page, nb.first, normalise(shown, dir),
                                normalise(real:gsub(dir:gsub("%p", "%%%0"), "."), dir)))
          else
            print(string.format("ok   %s:%d: the output shown is the real one", page, nb.first))
          end
        end
      end
    end
  end
  if #replacements > 0 then
    for k = #replacements, 1, -1 do
      local r = replacements[k]
      local new = {}
      for x = 1, r[1] do new[#new + 1] = lines[x] end
      for l in (r[3] .. "\n"):gmatch("(.-)\n") do new[#new + 1] = l end
      for x = r[2], #lines do new[#new + 1] = lines[x] end
      lines = new
    end
    local f = assert(io.open(path, "w"))
    f:write(table.concat(lines, "\n") .. "\n")
    f:close()
    changed = changed + #replacements
    print("updated " .. #replacements .. " output block(s) in " .. page)
  end
end
-- The synopsis at the top of docs/command-line.md against the binary: every flag each command's
-- --help lists is in that command's synopsis lines, and every flag there is in its --help.
do
  local lines = {}
  for l in io.lines(src .. "/docs/command-line.md") do lines[#lines + 1] = l end
  local synopsis, inBlock = {}, false
  for _, l in ipairs(lines) do
    if l:match("^```") then
      if inBlock then break end
      inBlock = true
    elseif inBlock then
      synopsis[#synopsis + 1] = l
    end
  end
  local byCommand, current = {}, nil
  for _, l in ipairs(synopsis) do
    local cmd = l:match("^rm3d ([a-z]+)")
    if cmd then current = cmd end
    if current and not l:match("^rm3d %-") then byCommand[current] = (byCommand[current] or "") .. " " .. l end
  end
  local help = run(shellQuote(rm3d) .. " --help 2>&1")
  local section = help:match("Subcommands:\n(.*)$") or ""
  local commandsListed = {}
  for line in section:gmatch("[^\n]+") do
    local c = line:match("^  ([a-z]+)%s%s")
    if c then commandsListed[#commandsListed + 1] = c end
  end
  -- True when the flag occurs in the text as a whole word (not as the start of a longer flag).
  local function hasFlag(text, f)
    local at = 1
    while true do
      local s, e = text:find(f, at, true)
      if not s then return false end
      if not text:sub(e + 1, e + 1):match("[%w%-]") then return true end
      at = e + 1
    end
  end
  for _, cmd in ipairs(commandsListed) do
    local text = byCommand[cmd]
    if not text then
      failures = failures + 1
      print("FAIL docs/command-line.md: the synopsis has no line for `rm3d " .. cmd .. "`")
    else
      local flags = {}
      for line in run(shellQuote(rm3d) .. " " .. cmd .. " --help 2>&1"):gmatch("[^\n]+") do
        local first = line:match("^%s+(%-[^%s]+)")
        if first then
          for f in first:gmatch("[^,]+") do
            f = f:match("^(%-%-[%w%-]+)")
            if f and f ~= "--help" then flags[f] = true end
          end
        end
      end
      local missing, extra = {}, {}
      for f in pairs(flags) do
        if not hasFlag(text, f) then missing[#missing + 1] = f end
      end
      local seenExtra = {}
      for f in text:gmatch("%-%-[%w%-]+") do
        if not flags[f] and f ~= "--help" and not seenExtra[f] then
          seenExtra[f] = true
          extra[#extra + 1] = f
        end
      end
      table.sort(missing)
      table.sort(extra)
      if #missing > 0 or #extra > 0 then
        failures = failures + 1
        print(string.format("FAIL docs/command-line.md: `rm3d %s` synopsis against its --help: missing %s; not in --help %s",
                            cmd, table.concat(missing, " "), table.concat(extra, " ")))
      else
        print(string.format("ok   docs/command-line.md: the synopsis of `rm3d %s` has every flag of its --help", cmd))
      end
    end
  end
end

print(string.format("%d commands, %d shown outputs, %d failed%s", commands, outputs, failures,
                    update and string.format(", %d output block(s) rewritten", changed) or ""))
os.exit(failures == 0 and 0 or 1)
