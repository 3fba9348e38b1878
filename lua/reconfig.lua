-- Shapes as data and the graph planner of self-reconfiguration: from one configuration of modules
-- to another with the same modules, which connections to undock and which to dock.
--
-- A shape is a connection graph: its modules (names, and types where they matter) and its
-- connections, each two docks of two modules, as world.graph() and `rm3d run --graph` export
-- them:
--
--   local reconfig = require("reconfig")
--   local snake = reconfig.shape{modules = {"s1", "s2", "s3"},
--                                connections = {{"s1", "back", "s2", "front"}, {"s2", "back", "s3", "front"}}}
--   local plan = reconfig.plan(snake, target)   -- plan.ops: {op = "undock" | "dock", a, da, b, db}
--   print(reconfig.format(plan))
--
-- The planner is greedy common-subgraph matching (GreedyCM, after Hou and Shen's graph-based
-- reconfiguration planning): modules of one type are interchangeable, so each module is given a
-- role of the target, growing the largest connected part the two shapes share (connections with
-- the same dock names at both ends) first, then the next largest, until every module has a role.
-- The plan undocks the connections the target does not have and docks those it lacks. Finding
-- the fewest operations is NP-complete even for trees; this one is polynomial (about n^4 for n
-- modules at worst) and `lower_bound` says how far from the fewest a plan can be. Whether an
-- operation can be done (can the free end reach that dock?) is the executor's question, not
-- this file's.
local M = {}

-- Raises at the user's call: `level` 3 is the caller of the function that called fail.
local function fail(where, msg, level)
  error(where .. ": " .. msg, level or 3)
end

local function edgeKey(a, da, b, db)
  local x, y = a .. "." .. da, b .. "." .. db
  if x > y then x, y = y, x end
  return x .. "-" .. y
end

--- A connection's key, the same whichever end comes first: "a.dock-b.dock" with the smaller
--- "module.dock" first.
M.key = edgeKey

--- A shape from {modules = {...}, connections = {...}}: `modules` a list of names, or a table
--- name -> type (type names: modules of different types never take each other's roles);
--- `connections` a list of {a, dock_a, b, dock_b}. Checks every entry: an unknown module, a
--- module connected to itself, a dock used twice or a connection given twice is an error naming it.
function M.shape(t)
  if type(t) ~= "table" then fail("reconfig.shape", "expected a table {modules = ..., connections = ...}") end
  local s = {names = {}, types = {}, index = {}, edges = {}, byKey = {}, adj = {}}
  local mods = t.modules
  if type(mods) ~= "table" then fail("reconfig.shape", "modules: expected a list of names or a table name -> type") end
  local list = {}
  if #mods > 0 then
    for i, name in ipairs(mods) do
      if type(name) ~= "string" then fail("reconfig.shape", "modules[" .. i .. "]: expected a name (string)") end
      list[#list + 1] = {name, "module"}
    end
  else
    for name, ty in pairs(mods) do
      if type(name) ~= "string" or type(ty) ~= "string" then
        fail("reconfig.shape", "modules: expected name = type pairs of strings")
      end
      list[#list + 1] = {name, ty}
    end
    table.sort(list, function(x, y) return x[1] < y[1] end)
  end
  for _, m in ipairs(list) do
    if s.index[m[1]] then fail("reconfig.shape", "module '" .. m[1] .. "' is listed twice") end
    s.names[#s.names + 1] = m[1]
    s.index[m[1]] = #s.names
    s.types[m[1]] = m[2]
    s.adj[m[1]] = {}
  end
  local used = {}
  for i, c in ipairs(t.connections or {}) do
    local where = "connections[" .. i .. "]"
    if type(c) ~= "table" or #c ~= 4 then fail("reconfig.shape", where .. ": expected {a, dock_a, b, dock_b}") end
    local a, da, b, db = c[1], c[2], c[3], c[4]
    for k = 1, 4 do
      if type(c[k]) ~= "string" then fail("reconfig.shape", where .. "[" .. k .. "]: expected a string") end
    end
    if not s.index[a] then fail("reconfig.shape", where .. ": unknown module '" .. a .. "'") end
    if not s.index[b] then fail("reconfig.shape", where .. ": unknown module '" .. b .. "'") end
    if a == b then fail("reconfig.shape", where .. ": module '" .. a .. "' connected to itself") end
    for _, d in ipairs({a .. "." .. da, b .. "." .. db}) do
      if used[d] then fail("reconfig.shape", where .. ": dock " .. d .. " is in two connections") end
      used[d] = true
    end
    local e = {a = a, da = da, b = b, db = db}
    s.edges[#s.edges + 1] = e
    s.byKey[edgeKey(a, da, b, db)] = e
    table.insert(s.adj[a], {dock = da, peer = b, peerDock = db})
    table.insert(s.adj[b], {dock = db, peer = a, peerDock = da})
  end
  return s
end

--- The shape of a world now (world scripts): every module with its type, every engaged
--- connection once. `w` is the `world` table.
function M.from_world(w)
  local mods, names, conns, seen = {}, {}, {}, {}
  for _, m in ipairs(w.modules()) do
    mods[m.name] = m.type
    names[m.id] = m.name
  end
  local docksOf = {}  -- type -> its docks (world.module_type builds a table a call)
  for _, m in ipairs(w.modules()) do
    docksOf[m.type] = docksOf[m.type] or w.module_type(m.type).docks
    for _, d in ipairs(docksOf[m.type]) do
      local st = m:dock_state(d.name)
      if st.engaged and st.peer_module then
        local peer = names[st.peer_module]
        local key = edgeKey(m.name, d.name, peer, st.peer_dock)
        if not seen[key] then
          seen[key] = true
          conns[#conns + 1] = {m.name, d.name, peer, st.peer_dock}
        end
      end
    end
  end
  return M.shape{modules = mods, connections = conns}
end

-- Grows the common connected part from the pair (u in I, v in G), breadth-first over
-- connections whose dock names agree at both ends; returns the pairs, in the order found.
local function grow(I, G, u, v, takenI, takenG)
  local pairs_, inI, inG = {{u, v}}, {[u] = v}, {[v] = u}
  local head = 1
  while head <= #pairs_ do
    local x, y = pairs_[head][1], pairs_[head][2]
    head = head + 1
    for _, ex in ipairs(I.adj[x]) do
      local p = ex.peer
      if not takenI[p] and not inI[p] then
        for _, ey in ipairs(G.adj[y]) do
          local q = ey.peer
          if ey.dock == ex.dock and ey.peerDock == ex.peerDock and not takenG[q] and not inG[q] and
              I.types[p] == G.types[q] then
            inI[p], inG[q] = q, p
            pairs_[#pairs_ + 1] = {p, q}
            break
          end
        end
      end
    end
  end
  return pairs_
end

-- M.match's work; errors are raised `level` calls up (the user's call of match or plan).
local function match(I, G, level)
  if #I.names ~= #G.names then
    fail("reconfig.match", string.format("the shapes hold %d and %d modules; a plan needs the same modules",
                                         #I.names, #G.names), level)
  end
  local count = {}
  for _, n in ipairs(I.names) do count[I.types[n]] = (count[I.types[n]] or 0) + 1 end
  for _, n in ipairs(G.names) do count[G.types[n]] = (count[G.types[n]] or 0) - 1 end
  local types = {}
  for ty in pairs(count) do types[#types + 1] = ty end
  table.sort(types)  -- the first type that differs, whatever the table's order
  for _, ty in ipairs(types) do
    if count[ty] ~= 0 then
      fail("reconfig.match", "the shapes hold different numbers of '" .. ty .. "' modules", level)
    end
  end
  local role, takenI, takenG, left = {}, {}, {}, #I.names
  while left > 0 do
    local best
    for _, u in ipairs(I.names) do
      if not takenI[u] then
        for _, v in ipairs(G.names) do
          if not takenG[v] and I.types[u] == G.types[v] then
            local found = grow(I, G, u, v, takenI, takenG)
            if not best or #found > #best then best = found end
          end
        end
      end
    end
    for _, p in ipairs(best) do
      role[p[1]], takenI[p[1]], takenG[p[2]] = p[2], true, true
    end
    left = left - #best
  end
  return role
end

--- Gives every module of I a role (a module name) of G: the largest common connected part
--- first (ties: the first in module order). Returns role[module of I] = module of G.
function M.match(I, G)
  return match(I, G, 4)
end

--- The fewest dock operations any plan needs: connections of each kind (the pair of dock names)
--- can only be made or undone one at a time, and a kept connection keeps its kind.
function M.lower_bound(I, G)
  local count = {}
  local function kind(e)
    local x, y = e.da, e.db
    if x > y then x, y = y, x end
    return x .. "-" .. y
  end
  for _, e in ipairs(I.edges) do count[kind(e)] = (count[kind(e)] or 0) + 1 end
  for _, e in ipairs(G.edges) do count[kind(e)] = (count[kind(e)] or 0) - 1 end
  local n = 0
  for _, c in pairs(count) do n = n + math.abs(c) end
  return n
end

--- The plan from shape I to shape G: {ops = {...}, role = {module -> role}, kept = n,
--- lower_bound = n}. ops: first every undock ({op = "undock", a, da, b, db}: a connection of I
--- that G does not have), then every dock (a connection of G, its modules named as in I), each
--- in the order of the shapes' connections.
function M.plan(I, G)
  local role = match(I, G, 4)
  local moduleOf = {}
  for m, r in pairs(role) do moduleOf[r] = m end
  local want = {}
  for _, e in ipairs(G.edges) do
    local a, b = moduleOf[e.a], moduleOf[e.b]
    want[#want + 1] = {a = a, da = e.da, b = b, db = e.db, key = edgeKey(a, e.da, b, e.db)}
  end
  local wanted = {}
  for _, e in ipairs(want) do wanted[e.key] = true end
  local ops, kept = {}, 0
  for _, e in ipairs(I.edges) do
    if wanted[edgeKey(e.a, e.da, e.b, e.db)] then
      kept = kept + 1
    else
      ops[#ops + 1] = {op = "undock", e.a, e.da, e.b, e.db}
    end
  end
  for _, e in ipairs(want) do
    if not I.byKey[e.key] then ops[#ops + 1] = {op = "dock", e.a, e.da, e.b, e.db} end
  end
  return {ops = ops, role = role, kept = kept, lower_bound = M.lower_bound(I, G)}
end

--- The plan as text, one operation a line ("undock s4.back - s5.front"), then the roles that
--- differ from the module's own name and the counts.
function M.format(plan)
  local lines = {}
  for i, o in ipairs(plan.ops) do
    lines[#lines + 1] = string.format("%2d. %-6s %s.%s - %s.%s", i, o.op, o[1], o[2], o[3], o[4])
  end
  local roles = {}
  for m, r in pairs(plan.role) do
    if m ~= r then roles[#roles + 1] = m .. " as " .. r end
  end
  table.sort(roles)
  if #roles > 0 then lines[#lines + 1] = "roles: " .. table.concat(roles, ", ") end
  lines[#lines + 1] = string.format("%d operations (at least %d), %d connections kept", #plan.ops,
                                    plan.lower_bound, plan.kept)
  return table.concat(lines, "\n")
end

return M
