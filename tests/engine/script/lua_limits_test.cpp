// LuaVm limits: the budget cannot be caught or split, the pattern matcher matches the stock one
// and is bounded, soft memory cap with traceback, no finalizers, strict require, watchdog,
// UTF-8-safe fault texts, mailbox byte limit.
#include <doctest/doctest.h>

#include <chrono>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <lua.hpp>
#include <memory>
#include <vector>

#include "messaging/mailbox.h"
#include "script/lua_value.h"
#include "script/lua_vm.h"
#include "script/watchdog.h"

using rm3d::LuaVm;
namespace fs = std::filesystem;

namespace {
bool runString(LuaVm& vm, const char* code, std::string& err) {
  if (luaL_loadbufferx(vm.L(), code, std::strlen(code), "@probe.lua", "t") != LUA_OK) {
    err = lua_tostring(vm.L(), -1);
    lua_pop(vm.L(), 1);
    return false;
  }
  return vm.call(0, 0, err, "the test call");
}
bool has(const std::string& s, const char* needle) {
  return s.find(needle) != std::string::npos;
}

// Runs `code` (which returns a string) in a state and returns that string or "ERROR".
std::string evalIn(lua_State* L, const char* code) {
  if (luaL_loadstring(L, code) != LUA_OK || lua_pcall(L, 0, 1, 0) != LUA_OK) {
    std::string e = lua_tostring(L, -1) ? lua_tostring(L, -1) : "?";
    lua_pop(L, 1);
    return "ERROR " + e;
  }
  std::string out = lua_tostring(L, -1) ? lua_tostring(L, -1) : "(not a string)";
  lua_pop(L, 1);
  return out;
}
}  // namespace

TEST_CASE("pcall cannot swallow the instruction budget, nor can coroutines split it") {
  LuaVm vm;
  vm.setInstructionBudget(200000);
  std::string err;
  CHECK_FALSE(runString(vm, "while true do pcall(function() while true do end end) end", err));
  CHECK(has(err, "probe.lua:1: instruction budget exceeded"));
  CHECK_FALSE(runString(
      vm, "while true do xpcall(function() while true do end end, function(m) while true do end end) end",
      err));
  CHECK(has(err, "instruction budget exceeded"));
  // Each coroutine alone is under the budget; together they are not.
  CHECK_FALSE(runString(
      vm, "for k = 1, 100 do coroutine.resume(coroutine.create(function() for i = 1, 10000 do end end)) end",
      err));
  CHECK(has(err, "instruction budget exceeded"));
  // A failed coroutine swallowed just before returning still fails the call.
  CHECK_FALSE(runString(vm, "local co = coroutine.wrap(function() while true do end end) pcall(co)", err));
  CHECK(has(err, "instruction budget exceeded"));
  // And the next call has a fresh budget.
  CHECK(runString(vm,
                  "for i = 1, 10000 do end local co = coroutine.wrap(function() for i = 1, 1000 do end "
                  "return 1 end) assert(co() == 1)",
                  err));
}

TEST_CASE("our pattern matcher gives the stock Lua 5.4 results") {
  // The same cases run through our string.find/match/gmatch/gsub and the stock ones.
  static const char* kCases = R"LUA(
    local out = {}
    local function add(...) local t = table.pack(...) for i = 1, t.n do out[#out + 1] = tostring(t[i]) end out[#out + 1] = "|" end
    local function try(f, ...) local r = table.pack(pcall(f, ...)) if r[1] then add(table.unpack(r, 2, r.n)) else add("error") end end
    local subjects = {"hello world", "  trim me  ", "a,b,,c", "THE (quick) fox", "key = value", "[[nested [brackets] ]]",
      "x = 10, y = -2.5e3", "aaa", "", "f(a(b)c)d", "THE END", "abc\0def", "caf\195\169 \240\159\152\128", "one two  three",
      "2024-01-31", "%d%%", "a.b-c+d*e?f"}
    local patterns = {"o", "l+", "l*", "l-", "l?", "^h", "d$", "^$", "%a+", "%A+", "%d+", "%D", "%s+", "%S+", "%w+", "%W",
      "%l+", "%u+", "%p", "%x+", "%c", "%g+", "[aeiou]", "[^aeiou ]+", "[a-f]+", "[%a_][%w_]*", "[%]]", "[^%s]+", "(%w+) (%w+)",
      "(%w+)%s*=%s*(%w+)", "()ll()", "(a*(.)%w(%s*))", "%b()", "%b[]", "%f[%w]%w+", "%f[%W]", "(%a)%1", "(.)(.)%2%1", ".-",
      ".-b", "(.-),", "([^,]*)", "%d+%.?%d*", "[+-]?%d+", "x*", "^(%s*)(.-)(%s*)$", "%.", "[%.%-]", "a-b", "\0", "[\0-\31]",
      "\195\169", "[\128-\255]+", "%%", "[%d%%]+", "^(%d+)-(%d+)-(%d+)$", "(h)(e)(l)(l)(o)", "()", "[]]", "[^]]+", "[a-]", "[-a]+",
      "(", "%", "[a", "(()", "%b", "%f", "%1", "(a)%2", "%g", "%z"}
    for _, s in ipairs(subjects) do
      for _, p in ipairs(patterns) do
        try(string.find, s, p)
        try(string.find, s, p, 3)
        try(string.find, s, p, -4)
        try(string.find, s, p, 1, true)
        try(string.match, s, p)
        try(string.match, s, p, 2)
        try(function() local r = {} for a, b in string.gmatch(s, p) do r[#r + 1] = tostring(a) .. "/" .. tostring(b) if #r > 50 then break end end return table.concat(r, ";") end)
        try(string.gsub, s, p, "<%0>")
        try(string.gsub, s, p, "%1-%%", 2)
        try(string.gsub, s, p, {hello = "HI", a = false, o = 1})
        try(string.gsub, s, p, function(a, b) if a == "o" then return nil end return "[" .. tostring(a) .. "," .. tostring(b) .. "]" end)
      end
    end
    try(string.gsub, "abc", "%w", "%2")
    try(string.gsub, "abc", "%w", "%z")
    try(string.gsub, "abc", "%w", function() return {} end)
    try(string.gsub, "abc", "", "-")
    try(string.gsub, "hello world", "o", "0", 0)
    try(("x"):rep(300).find, ("x"):rep(300), ("(x)"):rep(33))
    try(string.find, ("a"):rep(300), ("a?"):rep(300) .. ("a"):rep(300))
    return table.concat(out, " ")
  )LUA";
  LuaVm ours;
  lua_State* stock = luaL_newstate();
  luaL_openlibs(stock);
  const std::string a = evalIn(ours.L(), kCases), b = evalIn(stock, kCases);
  lua_close(stock);
  CHECK(a.size() > 10000);
  CHECK(a.rfind("ERROR", 0) == std::string::npos);
  if (a != b) {
    size_t i = 0;
    while (i < a.size() && i < b.size() && a[i] == b[i]) ++i;
    const size_t from = i > 200 ? i - 200 : 0;
    INFO("ours:  ", a.substr(from, 400));
    INFO("stock: ", b.substr(from, 400));
    CHECK(a == b);
  }
}

TEST_CASE("a backtracking pattern is stopped by the budget, with file:line") {
  LuaVm vm;
  vm.setInstructionBudget(1000000);
  std::string err;
  const auto t0 = std::chrono::steady_clock::now();
  CHECK_FALSE(runString(vm, "local s = string.rep('a', 5000)\nreturn s:find('.-.-.-.-.-.-b')", err));
  CHECK(std::chrono::steady_clock::now() - t0 < std::chrono::seconds(5));
  CHECK(has(err, "probe.lua:2: instruction budget exceeded in pattern matching"));
  CHECK(has(err, "stack traceback"));
  CHECK_FALSE(runString(vm, "string.gsub(string.rep('a', 3000), '(a-)-b', function() end)", err));
  CHECK(has(err, "instruction budget exceeded"));
  // Deep recursion in the matcher is refused, not a crash.
  CHECK_FALSE(runString(vm, "string.find(string.rep('a', 1000), string.rep('a?', 1000) .. '$')", err));
  CHECK(has(err, "pattern too complex"));
}

TEST_CASE("the memory cap is soft: the error names file:line and has a traceback") {
  LuaVm vm(4u << 20);
  std::string err;
  CHECK_FALSE(runString(vm, "local t = {}\nfor i = 1, 1e7 do t[i] = {i} end", err));
  CHECK(has(err, "probe.lua:2: out of memory: the module's memory cap is 4 MiB"));
  CHECK(has(err, "stack traceback"));
  CHECK(runString(vm, "local s = 0 for i = 1, 10 do s = s + i end", err));  // the garbage is collected
  // string.rep checks the size before building the string.
  CHECK_FALSE(runString(vm, "local s = string.rep('x', 1e9)", err));
  CHECK(has(err, "probe.lua:1: out of memory: string.rep would take 1000000000 bytes"));
  // table.concat and string.format are bounded by the cap too.
  CHECK_FALSE(runString(vm,
                        "local t = {} for i = 1, 64 do t[i] = string.rep('y', 100000) end\nlocal s = t\nfor "
                        "k = 1, 10 do s = {table.concat(s)} s[2] = s[1] end",
                        err));
  CHECK(has(err, "out of memory"));
  LuaVm world(4u << 20);
  world.setOwnerLabel("world script");
  CHECK_FALSE(runString(world, "local t = {} for i = 1, 1e7 do t[i] = {i} end", err));
  CHECK(has(err, "the world script's memory cap is 4 MiB"));
}

TEST_CASE("finalizers are refused, so closing a VM cannot hang") {
  std::string err;
  {
    LuaVm vm;
    vm.setInstructionBudget(100000);
    CHECK_FALSE(runString(vm, "local t = setmetatable({}, {__gc = function() while true do end end})", err));
    CHECK(has(err, "probe.lua:1: setmetatable: a metatable with __gc is not allowed"));
    // Adding __gc later does not mark the object for finalization (Lua 5.4 semantics).
    CHECK(runString(vm,
                    "local mt = {} g = setmetatable({}, mt) mt.__gc = function() while true do end end g = "
                    "nil collectgarbage()",
                    err));
  }  // lua_close returns
  CHECK(true);
}

TEST_CASE("an unprotected-looking callback look-up or metamethod cannot abort: protect() runs it") {
  LuaVm vm;
  std::string err;
  CHECK(runString(vm, "setmetatable(_G, {__index = function(_, k) error('no global ' .. k) end})", err));
  auto lookUp = [](lua_State* L) -> int {
    lua_getglobal(L, "step");  // runs the __index above
    return 1;
  };
  CHECK_FALSE(vm.protect(lookUp, nullptr, 1, err));
  CHECK(has(err, "probe.lua:1: no global step"));
  CHECK(lua_gettop(vm.L()) == 0);
}

TEST_CASE("require: dot-separated names only, and nothing that resolves outside its folders") {
  const fs::path dir = fs::temp_directory_path() / "rm3d_require_test";
  fs::remove_all(dir);
  fs::create_directories(dir / "inside");
  fs::create_directories(dir / "outside");
  std::ofstream(dir / "outside" / "secret.lua") << "return 'secret'";
  std::ofstream(dir / "inside" / "fine.lua") << "return 'fine'";
  std::error_code ec;
  fs::create_symlink(dir / "outside" / "secret.lua", dir / "inside" / "link.lua", ec);
  LuaVm vm;
  vm.setRequirePath({(dir / "inside").string()});
  std::string err;
  CHECK(runString(vm, "assert(require('fine') == 'fine')", err));
  for (const char* bad :
       {"require('.tmp.x')", "require('../outside/secret')", "require('/etc/passwd')", "require('a..b')",
        "require('a.')", "require('1abc')", "require('a-b')", "require('')"}) {
    CHECK_FALSE(runString(vm, bad, err));
    CHECK(has(err, "probe.lua:1: require: bad module name"));
  }
  if (!ec) {
    CHECK_FALSE(runString(vm, "require('link')", err));
    CHECK(has(err, "probe.lua:1: require: '"));
    CHECK(has(err, "link.lua' leads outside the folders"));
  }
  fs::remove_all(dir);
}

TEST_CASE("fault texts are valid UTF-8") {
  LuaVm vm;
  std::string err;
  CHECK_FALSE(runString(vm, "error('bad \\255 byte \\195\\169 ok')", err));
  CHECK(has(err, "probe.lua:1: bad \xEF\xBF\xBD byte \xC3\xA9 ok"));
  std::string s = "a\xff\xc3(\xe2\x82\xac\xed\xa0\x80\xf0\x9f\x98\x80z";
  rm3d::makeValidUtf8(s);
  const std::string r = "\xEF\xBF\xBD";  // U+FFFD
  CHECK(s == "a" + r + r + "(\xe2\x82\xac" + r + r + r + "\xf0\x9f\x98\x80z");
}

TEST_CASE("the watchdog interrupts a call that does not return in time") {
  rm3d::Watchdog dog(0.2);
  LuaVm vm;  // no instruction budget: only the watchdog can stop it
  vm.setWatchdog(&dog);
  std::string err;
  const auto t0 = std::chrono::steady_clock::now();
  CHECK_FALSE(runString(vm, "local x = 0\nwhile true do x = x + 1 end", err));
  const double s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  CHECK(s >= 0.15);
  CHECK(s < 3.0);
  CHECK(has(err, "probe.lua:2: watchdog: the test call did not return within 0.2 s"));
  CHECK(has(err, "stack traceback"));
  // pcall cannot catch it either, and the next call runs normally.
  CHECK_FALSE(runString(vm, "while true do pcall(function() while true do end end) end", err));
  CHECK(has(err, "watchdog"));
  CHECK(runString(vm, "for i = 1, 1000 do end", err));
  vm.setWatchdog(nullptr);
}

TEST_CASE("the watchdog watches VMs past its first block of slots and in a slot given back") {
  rm3d::Watchdog dog(0.2);
  std::vector<std::unique_ptr<LuaVm>> vms;
  for (int i = 0; i < 1100; ++i) {  // slots 0..1099: two blocks of 1024
    vms.push_back(std::make_unique<LuaVm>());
    vms.back()->setWatchdog(&dog);
  }
  vms[5].reset();  // its slot goes back to the watchdog
  LuaVm late;      // and is the next one given out
  late.setWatchdog(&dog);
  std::string err;
  for (LuaVm* vm : {&late, vms[1099].get()}) {
    vm->setInstructionBudget(1'000'000'000);  // a watchdog that missed it: an error, not a hang
    CHECK_FALSE(runString(*vm, "while true do end", err));
    CHECK(has(err, "watchdog: the test call did not return within 0.2 s"));
    CHECK(runString(*vm, "for i = 1, 1000 do end", err));  // the next call runs normally
  }
  // A VM that left the watchdog is not stopped by it (an instruction budget ends this one).
  vms[1099]->setWatchdog(nullptr);
  vms[1099]->setInstructionBudget(50'000'000);
  CHECK_FALSE(runString(*vms[1099], "while true do end", err));
  CHECK(has(err, "instruction"));
  CHECK_FALSE(has(err, "watchdog"));
}

TEST_CASE("unread messages count against the mailbox limit; the overflow is reported once") {
  rm3d::Mailbox box;
  auto message = [] {
    rm3d::Message m;
    m.dock = 0;
    m.data.type = rm3d::LuaValue::Type::String;
    m.data.string.assign(1000, 'x');
    return m;
  };
  using A = rm3d::Mailbox::Accept;
  int ok = 0;
  while (box.accept(message(), 10000) == A::Ok) ++ok;
  CHECK(ok == 9);
  CHECK(box.accept(message(), 10000) == A::Dropped);
  CHECK(box.dropped == 2);
  box.deliver(1);
  rm3d::Message out;
  CHECK(box.take(-1, out));
  CHECK(box.accept(message(), 10000) == A::Ok);  // room again after a read
  CHECK(box.bytes <= 10000);
}

#include "../test_world.h"
#include "core/error.h"

TEST_CASE("the world VM has a memory cap and a watchdog too") {
  rm3d::RunOptions o = rm3d::test::options();
  o.worldMemoryLimit = 8u << 20;
  try {
    rm3d::test::makeWorld("local t = {}\nfor i = 1, 1e8 do t[i] = {i} end", o);
    CHECK(false);
  } catch (const rm3d::InputError& e) {
    CHECK(has(e.what(), "test_world.lua:2: out of memory: the world script's memory cap is 8 MiB"));
  }
  o = rm3d::test::options();
  o.watchdogSeconds = 0.3;
  o.worldBudget = 0;  // only the watchdog can stop it
  try {
    rm3d::test::makeWorld("local x = 0\nwhile true do x = x + 1 end", o);
    CHECK(false);
  } catch (const rm3d::InputError& e) {
    CHECK(has(e.what(),
              "test_world.lua:2: watchdog: the world script's top level did not return within 0.3 s"));
  }
}
