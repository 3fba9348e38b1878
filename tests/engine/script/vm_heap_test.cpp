// VmHeap: blocks keep their bytes through every move between classes and the heap, freed blocks
// are reused by their own class, and a VM on it runs and frees everything.
#include "script/vm_heap.h"

#include <doctest/doctest.h>

#include <cstdint>
#include <cstring>
#include <vector>

#include "script/lua_vm.h"

extern "C" {
#include <lauxlib.h>
#include <lua.h>
}

namespace {

void fill(void* p, size_t n, uint8_t seed) {
  for (size_t i = 0; i < n; ++i) static_cast<uint8_t*>(p)[i] = uint8_t(seed + i);
}
bool holds(const void* p, size_t n, uint8_t seed) {
  for (size_t i = 0; i < n; ++i)
    if (static_cast<const uint8_t*>(p)[i] != uint8_t(seed + i)) return false;
  return true;
}

}  // namespace

TEST_CASE("VmHeap keeps a block's bytes as it grows and shrinks through classes and the heap") {
  rm3d::VmHeap heap;
  size_t size = 8;
  void* p = heap.realloc(nullptr, 0, size);
  REQUIRE(p);
  CHECK(reinterpret_cast<uintptr_t>(p) % 16 == 0);
  fill(p, size, 7);
  // 8 -> 24 -> 520 (the heap) -> 4000 -> 100 (a class again) -> 16 -> 15 (the same class).
  for (size_t next : {24, 520, 4000, 100, 16, 15}) {
    void* q = heap.realloc(p, size, next);
    REQUIRE(q);
    CHECK(reinterpret_cast<uintptr_t>(q) % 16 == 0);
    CHECK(holds(q, std::min(size, next), 7));
    fill(q, next, 7);
    p = q;
    size = next;
  }
  CHECK(heap.realloc(p, size, 0) == nullptr);
}

TEST_CASE("VmHeap gives a freed block back to its own class, last freed first") {
  if (!rm3d::VmHeap::pooled()) return;  // (AddressSanitizer: the heap's own rules)
  rm3d::VmHeap heap;
  void* a = heap.realloc(nullptr, 0, 40);  // class of 48 bytes
  void* b = heap.realloc(nullptr, 0, 48);
  void* c = heap.realloc(nullptr, 0, 200);
  REQUIRE((a && b && c));
  CHECK(a != b);
  heap.realloc(a, 40, 0);
  heap.realloc(b, 48, 0);
  CHECK(heap.realloc(nullptr, 0, 33) == b);  // 33 bytes: the same class, the last freed
  CHECK(heap.realloc(nullptr, 0, 47) == a);
  void* d = heap.realloc(nullptr, 0, 40);  // none free in the class: a new one
  CHECK(d != a);
  CHECK(d != b);
  // Same class: the block stays where it is.
  CHECK(heap.realloc(c, 200, 199) == c);
}

TEST_CASE("a VM on its own heap builds, collects and closes") {
  rm3d::LuaVm vm;
  lua_State* L = vm.L();
  REQUIRE(luaL_loadstring(L, R"(
    local t = {}
    for i = 1, 20000 do t[i] = {i, tostring(i), function() return i end} end
    local s = 0
    for i = 1, #t, 7 do s = s + t[i][3]() + #t[i][2] end
    t = nil
    collectgarbage()
    local u = {}
    for i = 1, 1000 do u[#u + 1] = string.rep("x", i) end
    return s + #u[1000]
  )") == LUA_OK);
  std::string err;
  REQUIRE(vm.call(0, 1, err));
  // sum over i = 1, 8, ..., 19993 of i + digits(i), then 1000.
  double want = 1000;
  for (int i = 1; i <= 20000; i += 7) want += i + double(std::to_string(i).size());
  CHECK(lua_tonumber(L, -1) == want);
  lua_pop(L, 1);
}
