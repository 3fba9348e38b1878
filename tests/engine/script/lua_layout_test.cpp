// script/lua_layout.h: the places of Lua's fields hold what Lua's calls made, and the walk from a
// step function finds what its calls read, leaving the state as it was.
#include "script/lua_layout.h"

#include <doctest/doctest.h>

#include <algorithm>
#include <cstring>
#include <lua.hpp>
#include <string>
#include <vector>

#include "core/read_at.h"

namespace lua_layout = rm3d::lua_layout;
using rm3d::readAt;

namespace {

bool has(const std::vector<const void*>& lines, const void* p) {
  return std::find(lines.begin(), lines.end(), p) != lines.end();
}

/// The node where short-string key `key` of the table at `index` has its main position.
const void* keyNode(lua_State* L, int index, const char* key) {
  const char* t = static_cast<const char*>(lua_topointer(L, index));
  lua_pushstring(L, key);
  const char* ts = lua_tostring(L, -1) - lua_layout::kStringContents;
  lua_pop(L, 1);
  const unsigned size = 1u << readAt<unsigned char>(t, lua_layout::kTableSizeNode);
  return readAt<const char*>(t, lua_layout::kTableNode) +
         lua_layout::kNodeBytes * (readAt<unsigned>(ts, lua_layout::kStringHash) & (size - 1));
}

/// The walk from the global function `step` (left on the stack), checked to leave the stack and
/// the collector's byte count as they were: it runs no Lua and allocates nothing.
std::vector<const void*> walkFromStep(lua_State* L) {
  lua_gc(L, LUA_GCCOLLECT);
  const int kb = lua_gc(L, LUA_GCCOUNT), bytes = lua_gc(L, LUA_GCCOUNTB);
  lua_getglobal(L, "step");
  const int top = lua_gettop(L);
  std::vector<const void*> lines;
  lua_layout::hotLines(L, 256, lines);
  CHECK(lua_gettop(L) == top);
  CHECK(lua_gc(L, LUA_GCCOUNT) == kb);
  CHECK(lua_gc(L, LUA_GCCOUNTB) == bytes);
  return lines;
}

const char* const kChunk = R"(
state = {start = 1, unused = 2}
local t = {x = 1}
local items = {{}, {}}
local helper = {}
function helper.wave(a) return math.sin(a) + math.pi end
function step()
  return state.start + t.x + #items + helper.wave(1) + math.abs(-1)
end
)";

}  // namespace

TEST_CASE("lua layout: the places hold what this Lua's calls made") {
  CHECK(lua_layout::mismatch() == "");
  CHECK(lua_layout::usable());
}

TEST_CASE("lua layout: the walk from a step function finds what its call reads") {
  lua_State* L = luaL_newstate();
  luaL_openlibs(L);
  REQUIRE(luaL_dostring(L, kChunk) == LUA_OK);
  const std::vector<const void*> lines = walkFromStep(L);
  CHECK(lua_type(L, -1) == LUA_TFUNCTION);

  CHECK(has(lines, lua_topointer(L, -1)));  // the function itself
  lua_pushglobaltable(L);
  CHECK(has(lines, lua_topointer(L, -1)));     // its _ENV
  CHECK(has(lines, keyNode(L, -1, "state")));  // the globals it names, each at its node
  CHECK(has(lines, keyNode(L, -1, "math")));
  lua_getfield(L, -1, "state");
  CHECK(has(lines, lua_topointer(L, -1)));
  CHECK(has(lines, keyNode(L, -1, "start")));
  lua_pop(L, 1);
  lua_getfield(L, -1, "math");
  CHECK(has(lines, lua_topointer(L, -1)));
  CHECK(has(lines, keyNode(L, -1, "abs")));  // named by step
  CHECK(has(lines, keyNode(L, -1, "sin")));  // named by helper.wave, met later in the walk
  CHECK(has(lines, keyNode(L, -1, "pi")));
  lua_pop(L, 2);
  // Its upvalues: t (and t.x's node), items and each item, helper and helper.wave.
  for (int i = 1;; ++i) {
    const char* name = lua_getupvalue(L, -1, i);
    if (!name) break;
    if (std::strcmp(name, "t") == 0) {
      CHECK(has(lines, lua_topointer(L, -1)));
      CHECK(has(lines, keyNode(L, -1, "x")));
    } else if (std::strcmp(name, "items") == 0) {
      CHECK(has(lines, lua_topointer(L, -1)));
      lua_rawgeti(L, -1, 2);
      CHECK(has(lines, lua_topointer(L, -1)));
      lua_pop(L, 1);
    } else if (std::strcmp(name, "helper") == 0) {
      CHECK(has(lines, lua_topointer(L, -1)));
      lua_getfield(L, -1, "wave");
      CHECK(has(lines, lua_topointer(L, -1)));
      lua_pop(L, 1);
    }
    lua_pop(L, 1);
  }
  // Nothing that step does not name: the `unused` entry's node (where no other key lies).
  lua_getglobal(L, "state");
  if (keyNode(L, -1, "unused") != keyNode(L, -1, "start")) CHECK_FALSE(has(lines, keyNode(L, -1, "unused")));
  lua_pop(L, 1);

  // At most `budget` lines in all.
  std::vector<const void*> few(3, nullptr);
  lua_layout::hotLines(L, 10, few);
  CHECK(few.size() == 10);
  // Only a Lua function is walked.
  std::vector<const void*> none;
  lua_pushcfunction(L, [](lua_State*) { return 0; });
  lua_layout::hotLines(L, 256, none);
  lua_pushinteger(L, 1);
  lua_layout::hotLines(L, 256, none);
  CHECK(none.empty());
  lua_close(L);
}

TEST_CASE("lua layout: a method call's table, through the metatable's __index") {
  lua_State* L = luaL_newstate();
  luaL_openlibs(L);
  REQUIRE(luaL_dostring(L, R"(
local methods = {get = function() return 3 end}
local handle = setmetatable({}, {__index = methods})
function step() return handle:get() end
)") == LUA_OK);
  lua_getglobal(L, "step");
  std::vector<const void*> lines;
  lua_layout::hotLines(L, 256, lines);
  lua_getupvalue(L, -1, 1);  // handle
  REQUIRE(lua_getmetatable(L, -1));
  CHECK(has(lines, lua_topointer(L, -1)));
  CHECK(has(lines, keyNode(L, -1, "__index")));
  lua_getfield(L, -1, "__index");
  CHECK(has(lines, lua_topointer(L, -1)));
  CHECK(has(lines, keyNode(L, -1, "get")));
  lua_close(L);
}

TEST_CASE("lua layout: the registry's slot of a reference") {
  lua_State* L = luaL_newstate();
  lua_newtable(L);
  const int ref = luaL_ref(L, LUA_REGISTRYINDEX);
  const void* slot = lua_layout::arraySlot(L, LUA_REGISTRYINDEX, ref);
  REQUIRE(slot != nullptr);
  const char* registry = static_cast<const char*>(lua_topointer(L, LUA_REGISTRYINDEX));
  CHECK(slot == readAt<const char*>(registry, lua_layout::kTableArray) + lua_layout::kValueBytes * (ref - 1));
  CHECK(lua_layout::arraySlot(L, LUA_REGISTRYINDEX, 0) == nullptr);
  CHECK(lua_layout::arraySlot(L, LUA_REGISTRYINDEX, 1 << 20) == nullptr);
  lua_pushinteger(L, 1);
  CHECK(lua_layout::arraySlot(L, -1, 1) == nullptr);
  lua_close(L);
}

TEST_CASE("lua layout: a large table is walked only so far, the stack left as it was") {
  lua_State* L = luaL_newstate();
  luaL_openlibs(L);
  // step names the first key the table's iteration meets and its 1000th.
  REQUIRE(luaL_dostring(L, R"(
big = {}
for i = 1, 100000 do big["k" .. i] = i end
local order = {}
for k in next, big do
  order[#order + 1] = k
  if #order == 1000 then break end
end
early, late = order[1], order[1000]
step = load("return function() return big." .. early .. " + big." .. late .. " end")()
)") == LUA_OK);
  const std::vector<const void*> lines = walkFromStep(L);
  CHECK(has(lines, lua_topointer(L, -1)));
  lua_getglobal(L, "big");
  CHECK(has(lines, lua_topointer(L, -1)));  // the table itself
  lua_getglobal(L, "early");
  lua_getglobal(L, "late");
  const std::string early = lua_tostring(L, -2), late = lua_tostring(L, -1);
  lua_pop(L, 2);
  // Its entries only so far: the node of the key met first, not that of the key met 1000th.
  CHECK(has(lines, keyNode(L, -1, early.c_str())));
  CHECK_FALSE(has(lines, keyNode(L, -1, late.c_str())));
  lua_close(L);
}
