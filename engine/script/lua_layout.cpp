// The places of script/lua_layout.h, their check, and the walk that finds a call's lines.
#include "script/lua_layout.h"

#include <cstdint>
#include <cstring>
#include <lua.hpp>

#include "core/read_at.h"

namespace rm3d::lua_layout {

namespace {

constexpr int kNodeKeyTag = 9;  // a Node's key tag, then (at 16) its key
constexpr int kNodeKey = 16;
constexpr unsigned char kFloatTag = 0x13;  // LUA_VNUMFLT
// The walk: this many levels of objects below the function; of a prototype's code and
// constants, at most these many bytes and entries; of a table's array part, these many slots.
constexpr int kDepth = 4;
constexpr int kCodeBytes = 1024;
constexpr int kConstants = 64;
constexpr int kArraySlots = 8;
// Of a table's entries, at most this many are looked at (a table of a million entries that a
// step reaches is walked no further than a small one).
constexpr int kEntries = 256;
constexpr int kUpvalues = 16;
constexpr int kObjects = 64;
constexpr int kKeys = 128;

/// The walk from a function over what its calls read (hotLines). Run twice: the first time only to
/// gather the string constants of the functions met (a function met late may name a key of a
/// table met early: a gait helper's math.sin), the second to note the lines.
struct Walk {
  Walk(lua_State* state, size_t lines, std::vector<const void*>& into) : L(state), budget(lines), out(into) {}
  lua_State* L;
  size_t budget;
  std::vector<const void*>& out;
  bool noting = false;
  // Objects visited in this pass, and the string constants met (their contents): at most
  // kObjects and kKeys (on the stack: a step's walk allocates nothing either).
  const void* seen[kObjects] = {};
  int seenCount = 0;
  const char* keys[kKeys] = {};
  int keyCount = 0;

  void note(const void* p) {
    if (noting && p && out.size() < budget) out.push_back(p);
  }
  /// True the first time p is met in this pass (and while there is room to remember it).
  bool first(const void* p) {
    for (int i = 0; i < seenCount; ++i)
      if (seen[i] == p) return false;
    if (seenCount == kObjects) return false;
    seen[seenCount++] = p;
    return true;
  }
  void noteKey(const char* contents) {
    if (isKey(contents) || keyCount == kKeys) return;
    keys[keyCount++] = contents;
  }
  bool isKey(const char* contents) const {
    for (int i = 0; i < keyCount; ++i)
      if (keys[i] == contents) return true;
    return false;
  }

  /// The value on top of the stack (left there).
  void value(int depth) {
    switch (lua_type(L, -1)) {
      case LUA_TFUNCTION:
        if (lua_iscfunction(L, -1))
          note(lua_topointer(L, -1));
        else
          closure(depth);
        break;
      case LUA_TTABLE:
        table(depth, false);
        break;
      case LUA_TUSERDATA:
        userdata(depth);
        break;
      default:
        break;
    }
  }

  void closure(int depth) {
    const char* cl = static_cast<const char*>(lua_topointer(L, -1));
    if (!first(cl)) return;
    note(cl);
    const int upvalues = readAt<uint8_t>(cl, kClosureUpvalueCount);
    for (int i = 0; i < upvalues && i < kUpvalues; ++i)
      note(readAt<const void*>(cl, kClosureUpvalues + 8 * i));
    const char* p = readAt<const char*>(cl, kClosureProto);
    note(p);
    note(p + kProtoCode);
    const char* code = readAt<const char*>(p, kProtoCode);
    const int codeBytes = 4 * readAt<int>(p, kProtoCodeCount);
    for (int at = 0; at < codeBytes && at < kCodeBytes; at += 64) note(code + at);
    const char* k = readAt<const char*>(p, kProtoConstants);
    const int constants = readAt<int>(p, kProtoConstantCount);
    for (int i = 0; i < constants && i < kConstants; ++i) {
      const char* kv = k + kValueBytes * i;
      if (i % 4 == 0) note(kv);
      if (readAt<uint8_t>(kv, kValueTag) != kShortStringTag) continue;
      const char* s = readAt<const char*>(kv, 0);
      note(s);
      noteKey(s + kStringContents);
    }
    if (depth >= kDepth) return;
    for (int i = 1; i <= upvalues && i <= kUpvalues; ++i) {
      if (!lua_getupvalue(L, -1, i)) break;
      value(depth + 1);
      lua_pop(L, 1);
    }
  }

  /// The node where key `contents` (interned in this state) lives in table t, if present: its
  /// main position, where a key without collisions is.
  const char* node(const char* t, const char* contents) const {
    const char* ts = contents - kStringContents;
    const unsigned size = 1u << readAt<uint8_t>(t, kTableSizeNode);
    return readAt<const char*>(t, kTableNode) + kNodeBytes * (readAt<unsigned>(ts, kStringHash) & (size - 1));
  }

  void table(int depth, bool meta) {
    const char* t = static_cast<const char*>(lua_topointer(L, -1));
    if (!first(t)) return;
    note(t);
    const unsigned slots = readAt<unsigned>(t, kTableArraySize);
    const char* array = readAt<const char*>(t, kTableArray);
    for (unsigned i = 0; i < slots && i < unsigned(kArraySlots); i += 64 / kValueBytes)
      note(array + kValueBytes * i);
    // Each entry whose key is a string constant met so far (the keys are interned: one string per
    // text in a state), and its value below; in a metatable, __index too (a method call's look-up
    // goes through it). lua_next, not a look-up by key: pushing a key string may run a step of the
    // collector, and the walk must change nothing.
    lua_pushnil(L);
    for (int entries = 0; lua_next(L, -2); ++entries) {
      if (entries == kEntries) {
        lua_pop(L, 2);  // the key and value: the iteration ends here
        break;
      }
      if (lua_type(L, -2) == LUA_TSTRING) {
        const char* key = lua_tostring(L, -2);
        if (isKey(key) || (meta && std::strcmp(key, "__index") == 0)) {
          note(node(t, key));
          if (depth < kDepth) value(depth + 1);
        }
      }
      lua_pop(L, 1);
    }
    for (int i = 1; depth < kDepth && unsigned(i) <= slots && i <= kArraySlots; ++i) {
      lua_rawgeti(L, -1, i);
      value(depth + 1);
      lua_pop(L, 1);
    }
    if (depth < kDepth && lua_getmetatable(L, -1)) {  // an object's methods
      table(depth + 1, true);
      lua_pop(L, 1);
    }
  }

  void userdata(int depth) {
    const void* u = lua_topointer(L, -1);
    if (!first(u)) return;
    note(u);
    if (depth < kDepth && lua_getmetatable(L, -1)) {
      table(depth + 1, true);
      lua_pop(L, 1);
    }
  }
};

}  // namespace

std::string mismatch() {
  lua_State* L = luaL_newstate();
  if (!L) return "no Lua state could be made";
  std::string out;
  auto check = [&](bool ok, const char* what) {
    if (!ok && out.empty()) out = what;
  };
  // A table of 3 array slots and 16 nodes, with t.x = 7.
  lua_createtable(L, 3, 16);
  const char* t = static_cast<const char*>(lua_topointer(L, -1));
  check(readAt<uint8_t>(t, kTableSizeNode) == 4, "kTableSizeNode: log2 of a table's node count");
  check(readAt<unsigned>(t, kTableArraySize) == 3, "kTableArraySize: a table's array size");
  check(readAt<const void*>(t, kTableArray) != nullptr, "kTableArray: a table's array part");
  const char* nodes = readAt<const char*>(t, kTableNode);
  check(nodes != nullptr && nodes != readAt<const char*>(t, kTableArray), "kTableNode: a table's nodes");
  lua_pushinteger(L, 7);
  lua_setfield(L, -2, "x");
  if (out.empty()) {
    lua_pushliteral(L, "x");
    const char* ts = lua_tostring(L, -1) - kStringContents;
    check(readAt<uint8_t>(ts, kStringLength) == 1, "kStringLength: a short string's length");
    const char* n = nodes + kNodeBytes * (readAt<unsigned>(ts, kStringHash) & 15u);
    check(readAt<uint8_t>(n, kNodeKeyTag) == kShortStringTag, "kStringHash: a key's node (its key tag)");
    check(readAt<const char*>(n, kNodeKey) == ts, "kStringContents: a key's node (its key)");
    check(readAt<int64_t>(n, 0) == 7, "kNodeBytes: a key's node (its value)");
    lua_pop(L, 1);
  }
  lua_pop(L, 1);
  // A closure of one upvalue with the constants "alpha", "beta" and 2.5.
  if (luaL_loadstring(L, "local u = {} return function() return u, 'alpha', 'beta', 2.5 end") != LUA_OK ||
      lua_pcall(L, 0, 1, 0) != LUA_OK) {
    check(false, "a scratch chunk did not run");
  } else if (out.empty()) {
    const char* cl = static_cast<const char*>(lua_topointer(L, -1));
    check(readAt<uint8_t>(cl, kClosureUpvalueCount) == 1, "kClosureUpvalueCount: a closure's upvalue count");
    check(readAt<const void*>(cl, kClosureUpvalues) != nullptr, "kClosureUpvalues: a closure's upvalue");
    const char* p = readAt<const char*>(cl, kClosureProto);
    check(p != nullptr, "kClosureProto: a closure's prototype");
    if (out.empty()) {
      check(readAt<int>(p, kProtoConstantCount) == 3, "kProtoConstantCount: a prototype's constant count");
      const int code = readAt<int>(p, kProtoCodeCount);
      check(code >= 3 && code <= 64 && readAt<const void*>(p, kProtoCode) != nullptr,
            "kProtoCodeCount, kProtoCode: a prototype's code");
      const char* k = readAt<const char*>(p, kProtoConstants);
      check(k != nullptr, "kProtoConstants: a prototype's constants");
      if (out.empty()) {
        const char* kv[3] = {k, k + kValueBytes, k + 2 * kValueBytes};
        check(readAt<uint8_t>(kv[0], kValueTag) == kShortStringTag &&
                  std::strcmp(readAt<const char*>(kv[0], 0) + kStringContents, "alpha") == 0 &&
                  std::strcmp(readAt<const char*>(kv[1], 0) + kStringContents, "beta") == 0,
              "kValueBytes, kValueTag, kStringContents: a prototype's string constants");
        check(readAt<uint8_t>(kv[2], kValueTag) == kFloatTag && readAt<double>(kv[2], 0) == 2.5,
              "kValueTag: a prototype's number constant");
      }
    }
  }
  lua_settop(L, 0);
  lua_pushboolean(L, 1);
  lua_pushboolean(L, 1);
  const char* stack = readAt<const char*>(L, kStateStack);
  check(stack != nullptr && readAt<const char*>(L, kStateTop) - stack == kValueBytes * (lua_gettop(L) + 1),
        "kStateStack, kStateTop: the state's stack");
  lua_close(L);
  return out;
}

bool usable() {
  static const bool ok = mismatch().empty();  // a property of the Lua linked in: set once
  return ok;
}

void hotLines(lua_State* L, size_t budget, std::vector<const void*>& out) {
  if (!usable() || lua_type(L, -1) != LUA_TFUNCTION || lua_iscfunction(L, -1)) return;
  if (!lua_checkstack(L, 4 * kDepth + 8)) return;
  const int top = lua_gettop(L);
  Walk w{L, budget, out};
  const char* stack = readAt<const char*>(L, kStateStack);
  w.closure(0);  // the constants, gathered
  w.seenCount = 0;
  w.noting = true;
  w.note(stack);
  w.note(stack + 64);
  w.closure(0);
  lua_settop(L, top);
}

const void* arraySlot(lua_State* L, int index, int i) {
  if (!usable() || lua_type(L, index) != LUA_TTABLE) return nullptr;
  const char* t = static_cast<const char*>(lua_topointer(L, index));
  if (i < 1 || unsigned(i) > readAt<unsigned>(t, kTableArraySize)) return nullptr;
  return readAt<const char*>(t, kTableArray) + kValueBytes * (i - 1);
}

}  // namespace rm3d::lua_layout
