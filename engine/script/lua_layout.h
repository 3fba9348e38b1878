// Where Lua 5.4 (Debian 12's 5.4.4) keeps what a behaviour's step() reads, for fetching it ahead
// (__builtin_prefetch). With a thousand VMs stepped one after another, each VM's objects have left
// the caches since its last step, and Lua reaches them through chains of pointers (a global's
// table, its hash node, the key's string; the function's constants, its upvalues), each load
// waiting on the one before: a 1000-module snake's behaviours took 4.2 us a module, of which about
// half was spent in the look-ups of string keys (luaH_getshortstr) waiting on memory, against 0.3
// us when the same VM's objects are in the caches.
//
// The objects' fields are Lua's own (lobject.h, lstate.h, not installed), so their places are
// written here and checked on a scratch state by mismatch() (tests/engine/script/lua_layout_test.cpp);
// hotLines() reads them only where that check passed, and only to make addresses to fetch: a fetch
// of a wrong or stale line is a fetch wasted, never a wrong result.
#pragma once

#include <string>
#include <vector>

struct lua_State;

namespace rm3d::lua_layout {

// Table (lobject.h).
constexpr int kTableSizeNode = 11;   ///< lsizenode: log2 of the hash part's node count
constexpr int kTableArraySize = 12;  ///< alimit: the array part's size
constexpr int kTableArray = 16;      ///< array: TValue[alimit]
constexpr int kTableNode = 24;       ///< node: Node[1 << lsizenode]
constexpr int kNodeBytes = 24;       ///< a Node: its value, key tag, chain link, key
constexpr int kValueBytes = 16;      ///< a TValue: value, then its tag
constexpr int kValueTag = 8;
constexpr unsigned char kShortStringTag = 0x44;  ///< LUA_VSHRSTR, collectable
// TString.
constexpr int kStringLength = 11;    ///< shrlen (short strings)
constexpr int kStringHash = 12;      ///< hash
constexpr int kStringContents = 24;  ///< contents: what lua_tostring returns
// LClosure.
constexpr int kClosureUpvalueCount = 10;  ///< nupvalues
constexpr int kClosureProto = 24;         ///< p
constexpr int kClosureUpvalues = 32;      ///< upvals: UpVal*[nupvalues]
// Proto.
constexpr int kProtoConstantCount = 20;  ///< sizek
constexpr int kProtoCodeCount = 24;      ///< sizecode (4-byte instructions)
constexpr int kProtoConstants = 56;      ///< k: TValue[sizek]
constexpr int kProtoCode = 64;           ///< code
// lua_State.
constexpr int kStateTop = 16;    ///< top
constexpr int kStateStack = 48;  ///< stack

/// Empty when every place above holds what Lua's public calls made or returned, on a scratch
/// state; else the first place that does not.
std::string mismatch();

/// Whether mismatch() is empty for the Lua this process runs with (checked once).
bool usable();

/// The cache lines a call of the Lua function on top of L's stack will read, as far as a walk from
/// it finds them within `budget` lines: the state's stack; the function, its upvalues, prototype,
/// code and constants; each table it reaches (through its upvalues, and from them by the string
/// constants of the functions met, by the array slots, and through metatables' __index), the node
/// where each such key lives; and so on a few levels deep. Only raw accesses, no allocation and no
/// Lua code run: the state is left as it was. Nothing when !usable(). The stack is unchanged.
void hotLines(lua_State* L, size_t budget, std::vector<const void*>& out);

/// Where slot i (from 1) of the array part of the table at `index` lies (the registry's slot of a
/// function kept by luaL_ref), or null (not in the array part, or !usable()).
const void* arraySlot(lua_State* L, int index, int i);

}  // namespace rm3d::lua_layout
