// require("linalg"): constructors, operators, decompositions, quaternions and transforms against
// known answers; errors name the line and the shapes; cost of one 6 x 9 DLS step.
#include <doctest/doctest.h>

#include <cstdio>
#include <cstring>
#include <ctime>
#include <lua.hpp>
#include <string>

#include "script/lua_vm.h"

using rm3d::LuaVm;

namespace {

/// Runs `code` as chunk "probe.lua"; returns "" on success or the error's first line.
std::string run(LuaVm& vm, const char* code) {
  if (luaL_loadbufferx(vm.L(), code, std::strlen(code), "@probe.lua", "t") != LUA_OK) {
    std::string e = lua_tostring(vm.L(), -1);
    lua_pop(vm.L(), 1);
    return e;
  }
  std::string err;
  if (vm.call(0, 0, err, "the test call")) return "";
  return err.substr(0, err.find('\n'));
}

}  // namespace

TEST_CASE("linalg: construction, access, operators") {
  LuaVm vm(32 << 20);
  vm.setInstructionBudget(10000000);
  CHECK(run(vm, R"(
    local linalg = require("linalg")
    assert(require("linalg") == linalg)
    local A = linalg.matrix{{1, 2}, {3, 4}}
    assert(A:rows() == 2 and A:cols() == 2 and A:get(2, 1) == 3 and #A == 2)
    local v = linalg.vector{1, 2}
    assert(#v == 2 and v:get(2) == 2)
    local Av = A * v
    assert(#Av == 2 and Av:get(1) == 5 and Av:get(2) == 11)
    assert(A * 2 == linalg.matrix{{2, 4}, {6, 8}} and 2 * A == A * 2)
    assert(A + A == A * 2 and (A - A) == linalg.zeros(2, 2) and -A == A * -1)
    assert(A * linalg.identity(2) == A and A:t() == linalg.matrix{{1, 3}, {2, 4}})
    assert(A / 2 == linalg.matrix{{0.5, 1}, {1.5, 2}})
    A:set(1, 2, 7); assert(A:get(1, 2) == 7)
    v:set(1, 5); assert(v:get(1) == 5)
    assert(tostring(linalg.vector{1, 2.5}) == "vector{1, 2.5}")
    assert(tostring(linalg.matrix{{1, 2}, {3, 4}}) == "matrix{{1, 2}, {3, 4}}")
    assert(linalg.vector{3, 4}:norm() == 5 and linalg.vector{1, 2}:dot(linalg.vector{3, 4}) == 11)
    local c = linalg.vector{1, 0, 0}:cross(linalg.vector{0, 1, 0})
    assert(c == linalg.vector{0, 0, 1})
    local t = linalg.matrix{{1, 2, 3}}:totable(); assert(#t == 1 and t[1][3] == 3)
    assert(linalg.zeros(3):rows() == 3 and linalg.vector(4):norm() == 0)
  )") == "");
}

TEST_CASE("linalg: inverse, determinant, solve, SVD, pseudo-inverse, DLS") {
  LuaVm vm(32 << 20);
  vm.setInstructionBudget(10000000);
  CHECK(run(vm, R"(
    local linalg = require("linalg")
    local function near(a, b, tol) return math.abs(a - b) <= (tol or 1e-12) end
    local function close(A, B, tol)
      if A:rows() ~= B:rows() or A:cols() ~= B:cols() then return false end
      for i = 1, A:rows() do for j = 1, A:cols() do
        if not near(A:get(i, j), B:get(i, j), tol or 1e-10) then return false end
      end end
      return true
    end
    local A = linalg.matrix{{4, 7}, {2, 6}}
    assert(near(A:det(), 10))
    assert(close(A:inv(), linalg.matrix{{0.6, -0.7}, {-0.2, 0.4}}))
    local x = A:solve(linalg.vector{1, 2})
    assert(close(A * x, linalg.vector{1, 2}) and #x == 2)
    -- SVD: U diag(s) V^T rebuilds a 3 x 2 matrix; s descending
    local B = linalg.matrix{{1, 2}, {3, 4}, {5, 6}}
    local U, s, V = B:svd()
    assert(U:rows() == 3 and U:cols() == 2 and #s == 2 and V:rows() == 2)
    assert(s:get(1) >= s:get(2))
    local S = linalg.zeros(2, 2); S:set(1, 1, s:get(1)); S:set(2, 2, s:get(2))
    assert(close(U * S * V:t(), B))
    -- pinv: B+ B = I (full column rank)
    assert(close(B:pinv() * B, linalg.identity(2)))
    -- DLS with lambda 0 on a full-row-rank 2 x 3 is the minimum-norm solution = pinv * b
    local J = linalg.matrix{{1, 0, 1}, {0, 1, 1}}
    local b = linalg.vector{1, 2}
    assert(close(J:dls(b, 0), J:pinv() * b))
    -- with lambda > 0: (J^T J + l^2 I) x = J^T b
    local l = 0.3
    local y = J:dls(b, l)
    assert(close((J:t() * J + linalg.identity(3) * (l * l)) * y, J:t() * b))
    -- tall system through the other branch
    local z = B:dls(linalg.vector{1, 1, 1}, l)
    assert(close((B:t() * B + linalg.identity(2) * (l * l)) * z, B:t() * linalg.vector{1, 1, 1}))
    -- least squares through solve on a tall matrix
    local w = B:solve(linalg.vector{1, 2, 3})
    assert(close(w, B:pinv() * linalg.vector{1, 2, 3}))
  )") == "");
}

TEST_CASE("linalg: quaternions and rigid transforms") {
  LuaVm vm(32 << 20);
  vm.setInstructionBudget(10000000);
  CHECK(run(vm, R"(
    local linalg = require("linalg")
    local function near(a, b) return math.abs(a - b) < 1e-12 end
    local q = linalg.quat_axis_angle({0, 0, 1}, math.pi / 2)
    local v = q:rotate(linalg.vector{1, 0, 0})
    assert(near(v:get(1), 0) and near(v:get(2), 1) and near(v:get(3), 0))
    local qq = q * q
    assert(near(qq:angle(), math.pi))
    local back = q:inv():rotate(v)
    assert(near(back:get(1), 1) and near(back:get(2), 0))
    local R = q:matrix(); assert(near(R:get(2, 1), 1) and near(R:det(), 1))
    local T = linalg.transform(q, {1, 2, 3})
    local p = T * linalg.vector{1, 0, 0}
    assert(near(p:get(1), 1) and near(p:get(2), 3) and near(p:get(3), 3))
    local I = T * T:inv()
    local t = I:translation()
    assert(near(t:norm(), 0) and near(I:rotation():angle(), 0))
    local M = T:matrix(); assert(M:rows() == 4 and near(M:get(1, 4), 1))
    local T2 = linalg.transform(R, linalg.vector{0, 0, 0})
    assert(near(T2:rotation():angle(), math.pi / 2))
    assert(linalg.quat(2, 0, 0, 0) == linalg.quat{1, 0, 0, 0})
  )") == "");
}

TEST_CASE("linalg: errors name the line and what was wrong") {
  LuaVm vm(32 << 20);
  vm.setInstructionBudget(10000000);
  CHECK(run(vm, "local l = require('linalg')\nlocal x = l.zeros(6, 9) * l.vector{1, 2, 3}") ==
        "probe.lua:2: linalg: shape mismatch: 6x9 * 3x1");
  CHECK(run(vm, "local l = require('linalg')\nlocal x = l.identity(2) + l.identity(3)") ==
        "probe.lua:2: linalg: shape mismatch: 2x2 + 3x3");
  CHECK(run(vm, "local l = require('linalg')\nlocal x = l.matrix{{1, 2}, {2, 4}}:inv()") ==
        "probe.lua:2: linalg: inv: singular matrix (2x2, rank 1)");
  CHECK(run(vm, "local l = require('linalg')\nlocal x = l.matrix{{1, 2}, {2, 4}}:solve(l.vector{1, 1})")
            .rfind("probe.lua:2: linalg: solve: singular matrix (2x2, rank 1)", 0) == 0);
  CHECK(run(vm, "local l = require('linalg')\nlocal x = l.vector{1, 2}:get(3)") ==
        "probe.lua:2: linalg: get: index 3 out of range (the vector has 2 entries)");
  CHECK(run(vm, "local l = require('linalg')\nlocal x = l.identity(2):get(0, 1)") ==
        "probe.lua:2: linalg: get: index (0, 1) out of range for a 2x2 matrix");
  CHECK(run(vm, "local l = require('linalg')\nlocal x = l.matrix(5)") ==
        "probe.lua:2: linalg: matrix: expected a table of rows ({{1, 2}, {3, 4}}), got number");
  CHECK(run(vm, "local l = require('linalg')\nlocal x = l.matrix{{1, 2}, {3}}") ==
        "probe.lua:2: linalg: matrix: row 2 has 1 entries, row 1 has 2");
  CHECK(run(vm, "local l = require('linalg')\nlocal x = l.matrix{{1, 'a'}}") ==
        "probe.lua:2: linalg: matrix: entry (1, 2): expected a number, got string");
  CHECK(run(vm, "local l = require('linalg')\nlocal x = l.identity(2):dls(l.vector{1, 2}, -1)") ==
        "probe.lua:2: linalg: dls: the damping lambda must be finite and >= 0, got -1.0");
  CHECK(run(vm, "local l = require('linalg')\nlocal x = l.identity(2) * 'x'") ==
        "probe.lua:2: linalg: cannot multiply matrix by string");
  CHECK(run(vm, "local l = require('linalg')\nlocal x = l.zeros(100000, 100000)")
            .rfind("probe.lua:2: linalg: zeros: bad size 100000x100000", 0) == 0);
  // Huge work is charged to the budget rather than stalling the call.
  LuaVm small(64 << 20);
  small.setInstructionBudget(100000);
  CHECK(run(small, "local l = require('linalg')\nlocal A = l.identity(400)\nlocal B = A * A")
            .find("instruction budget exceeded") != std::string::npos);
}

TEST_CASE("linalg: a 6 x 9 DLS step costs microseconds") {
  LuaVm vm(32 << 20);
  vm.setInstructionBudget(0);
  const char* code = R"(
    local linalg = require("linalg")
    local rows = {}
    for i = 1, 6 do rows[i] = {} for j = 1, 9 do rows[i][j] = math.sin(i * 9 + j) end end
    local J = linalg.matrix(rows)
    local e = linalg.vector{0.01, -0.02, 0.03, 0, 0.01, 0.02}
    local x
    for k = 1, 100000 do x = J:dls(e, 0.05) end
    assert(#x == 9)
  )";
  // CPU time of this process (the build machine is shared: wall time would count the others).
  const std::clock_t c0 = std::clock();
  CHECK(run(vm, code) == "");
  const double us = 1e6 * double(std::clock() - c0) / CLOCKS_PER_SEC / 1e5;
  MESSAGE("one 6x9 J:dls(e, lambda) from Lua, CPU time: " << us << " us");
}
