// Lua 5.4 pattern matching (string.find, match, gmatch, gsub) with its work charged to the
// VM's instruction budget. The stock matcher backtracks without bound in C, out of reach of
// the count hook: `("a"):rep(5000):find(".-.-.-.-.-.-b")` would run for years. This one has
// the same semantics (classes, sets, anchors, captures and position captures, %b, %f,
// back-references, quantifiers, gsub replacements) and counts each matching step; when the
// call's budget is spent (or the watchdog fires) it raises like the count hook does.
//
// Lua errors longjmp, so this file is written in C style: no objects with destructors.
//
// Derived from lstrlib.c of Lua 5.4 (its matcher: match, classes, sets, captures, gsub's
// replacements), under Lua's license:
//
// Copyright (C) 1994-2023 Lua.org, PUC-Rio.
//
// Permission is hereby granted, free of charge, to any person obtaining a copy of this software
// and associated documentation files (the "Software"), to deal in the Software without
// restriction, including without limitation the rights to use, copy, modify, merge, publish,
// distribute, sublicense, and/or sell copies of the Software, and to permit persons to whom the
// Software is furnished to do so, subject to the following conditions:
//
// The above copyright notice and this permission notice shall be included in all copies or
// substantial portions of the Software.
//
// THE SOFTWARE IS PROVIDED "AS IS", WITHOUT WARRANTY OF ANY KIND, EXPRESS OR IMPLIED, INCLUDING
// BUT NOT LIMITED TO THE WARRANTIES OF MERCHANTABILITY, FITNESS FOR A PARTICULAR PURPOSE AND
// NONINFRINGEMENT. IN NO EVENT SHALL THE AUTHORS OR COPYRIGHT HOLDERS BE LIABLE FOR ANY CLAIM,
// DAMAGES OR OTHER LIABILITY, WHETHER IN AN ACTION OF CONTRACT, TORT OR OTHERWISE, ARISING FROM,
// OUT OF OR IN CONNECTION WITH THE SOFTWARE OR THE USE OR OTHER DEALINGS IN THE SOFTWARE.
#include <cctype>
#include <cstddef>
#include <cstring>
#include <lua.hpp>

#include "script/lua_vm.h"

namespace rm3d {

namespace {

constexpr int kMaxCaptures = 32;
constexpr int kMaxCalls = 200;  // recursion depth of match(): "pattern too complex" beyond
constexpr int kCapUnfinished = -1;
constexpr int kCapPosition = -2;
constexpr char kEsc = '%';
constexpr const char* kSpecials = "^$*+?.([%-";
constexpr int64_t kChargeEvery = 4096;  // steps between charges to the budget

inline int uchar(char c) {
  return static_cast<unsigned char>(c);
}

struct MatchState {
  const char* srcInit;
  const char* srcEnd;
  const char* pEnd;
  lua_State* L;
  int matchDepth;
  int level;
  int64_t steps;
  struct {
    const char* init;
    ptrdiff_t len;
  } capture[kMaxCaptures];
};

void flushSteps(MatchState* ms) {
  const int64_t n = ms->steps;
  ms->steps = 0;
  LuaVm::charge(ms->L, n, "pattern matching");
}

inline void step(MatchState* ms, int64_t n = 1) {
  ms->steps += n;
  if (ms->steps >= kChargeEvery) flushSteps(ms);
}

const char* match(MatchState* ms, const char* s, const char* p);

int checkCapture(MatchState* ms, int l) {
  l -= '1';
  if (l < 0 || l >= ms->level || ms->capture[l].len == kCapUnfinished)
    return luaL_error(ms->L, "invalid capture index %%%d in pattern", l + 1);
  return l;
}

int captureToClose(MatchState* ms) {
  int level = ms->level;
  for (level--; level >= 0; level--)
    if (ms->capture[level].len == kCapUnfinished) return level;
  return luaL_error(ms->L, "invalid pattern capture (a ')' without '(')");
}

const char* classEnd(MatchState* ms, const char* p) {
  switch (*p++) {
    case kEsc:
      if (p == ms->pEnd) luaL_error(ms->L, "malformed pattern (ends with '%%')");
      return p + 1;
    case '[':
      if (*p == '^') p++;
      do {  // look for a ']'
        if (p == ms->pEnd) luaL_error(ms->L, "malformed pattern (missing ']')");
        if (*(p++) == kEsc && p < ms->pEnd) p++;  // skip escapes (e.g. '%]')
      } while (*p != ']');
      return p + 1;
    default:
      return p;
  }
}

int matchClass(int c, int cl) {
  int res;
  switch (std::tolower(cl)) {
    case 'a':
      res = std::isalpha(c);
      break;
    case 'c':
      res = std::iscntrl(c);
      break;
    case 'd':
      res = std::isdigit(c);
      break;
    case 'g':
      res = std::isgraph(c);
      break;
    case 'l':
      res = std::islower(c);
      break;
    case 'p':
      res = std::ispunct(c);
      break;
    case 's':
      res = std::isspace(c);
      break;
    case 'u':
      res = std::isupper(c);
      break;
    case 'w':
      res = std::isalnum(c);
      break;
    case 'x':
      res = std::isxdigit(c);
      break;
    default:
      return cl == c;
  }
  if (std::isupper(cl)) res = !res;
  return res;
}

/// p points at '[', ec at the closing ']'.
int matchBracketClass(int c, const char* p, const char* ec) {
  int sig = 1;
  if (*(p + 1) == '^') {
    sig = 0;
    p++;  // skip the '^'
  }
  while (++p < ec) {
    if (*p == kEsc) {
      p++;
      if (matchClass(c, uchar(*p))) return sig;
    } else if (*(p + 1) == '-' && p + 2 < ec) {
      p += 2;
      if (uchar(*(p - 2)) <= c && c <= uchar(*p)) return sig;
    } else if (uchar(*p) == c) {
      return sig;
    }
  }
  return !sig;
}

int singleMatch(MatchState* ms, const char* s, const char* p, const char* ep) {
  if (s >= ms->srcEnd) return 0;
  const int c = uchar(*s);
  switch (*p) {
    case '.':
      return 1;
    case kEsc:
      return matchClass(c, uchar(*(p + 1)));
    case '[':
      return matchBracketClass(c, p, ep - 1);
    default:
      return uchar(*p) == c;
  }
}

const char* matchBalance(MatchState* ms, const char* s, const char* p) {
  if (p >= ms->pEnd - 1) luaL_error(ms->L, "malformed pattern (missing arguments to '%%b')");
  if (s >= ms->srcEnd || *s != *p) return nullptr;
  const int b = *p, e = *(p + 1);
  int cont = 1;
  const char* start = s;
  while (++s < ms->srcEnd) {
    if (*s == e) {
      if (--cont == 0) {
        step(ms, (s - start) / 16);
        return s + 1;
      }
    } else if (*s == b) {
      cont++;
    }
  }
  step(ms, (s - start) / 16);
  return nullptr;
}

const char* maxExpand(MatchState* ms, const char* s, const char* p, const char* ep) {
  ptrdiff_t i = 0;  // counts maximum expand for item
  while (singleMatch(ms, s + i, p, ep)) i++;
  step(ms, i / 16);
  // Try with the maximum repetitions, then fewer.
  while (i >= 0) {
    const char* res = match(ms, s + i, ep + 1);
    if (res) return res;
    i--;  // else didn't match; reduce 1 repetition and try again
  }
  return nullptr;
}

const char* minExpand(MatchState* ms, const char* s, const char* p, const char* ep) {
  for (;;) {
    const char* res = match(ms, s, ep + 1);
    if (res != nullptr) return res;
    if (singleMatch(ms, s, p, ep))
      s++;  // try with one more repetition
    else
      return nullptr;
  }
}

const char* startCapture(MatchState* ms, const char* s, const char* p, int what) {
  const int level = ms->level;
  if (level >= kMaxCaptures) luaL_error(ms->L, "too many captures in pattern (at most %d)", kMaxCaptures);
  ms->capture[level].init = s;
  ms->capture[level].len = what;
  ms->level = level + 1;
  const char* res = match(ms, s, p);
  if (res == nullptr) ms->level--;  // undo capture
  return res;
}

const char* endCapture(MatchState* ms, const char* s, const char* p) {
  const int l = captureToClose(ms);
  ms->capture[l].len = s - ms->capture[l].init;  // close capture
  const char* res = match(ms, s, p);
  if (res == nullptr) ms->capture[l].len = kCapUnfinished;  // undo capture
  return res;
}

const char* matchCapture(MatchState* ms, const char* s, int l) {
  l = checkCapture(ms, l);
  const size_t len = size_t(ms->capture[l].len);
  step(ms, ptrdiff_t(len) / 16);
  if (size_t(ms->srcEnd - s) >= len && std::memcmp(ms->capture[l].init, s, len) == 0) return s + len;
  return nullptr;
}

const char* match(MatchState* ms, const char* s, const char* p) {
  if (ms->matchDepth-- == 0) luaL_error(ms->L, "pattern too complex (nested too deeply)");
init:  // using goto to optimize tail recursion
  step(ms);
  if (p != ms->pEnd) {
    switch (*p) {
      case '(':
        if (*(p + 1) == ')')
          s = startCapture(ms, s, p + 2, kCapPosition);
        else
          s = startCapture(ms, s, p + 1, kCapUnfinished);
        break;
      case ')':
        s = endCapture(ms, s, p + 1);
        break;
      case '$':
        if (p + 1 != ms->pEnd) goto dflt;  // not the last char: an ordinary '$'
        s = (s == ms->srcEnd) ? s : nullptr;
        break;
      case kEsc:
        switch (*(p + 1)) {
          case 'b':
            s = matchBalance(ms, s, p + 2);
            if (s != nullptr) {
              p += 4;
              goto init;
            }
            break;
          case 'f': {
            p += 2;
            if (*p != '[') luaL_error(ms->L, "missing '[' after '%%f' in pattern");
            const char* ep = classEnd(ms, p);
            const char previous = (s == ms->srcInit) ? '\0' : *(s - 1);
            const char current = (s < ms->srcEnd) ? *s : '\0';
            if (!matchBracketClass(uchar(previous), p, ep - 1) &&
                matchBracketClass(uchar(current), p, ep - 1)) {
              p = ep;
              goto init;
            }
            s = nullptr;
            break;
          }
          case '0':
          case '1':
          case '2':
          case '3':
          case '4':
          case '5':
          case '6':
          case '7':
          case '8':
          case '9':
            s = matchCapture(ms, s, uchar(*(p + 1)));
            if (s != nullptr) {
              p += 2;
              goto init;
            }
            break;
          default:
            goto dflt;
        }
        break;
      default:
      dflt : {
        const char* ep = classEnd(ms, p);  // points to the optional suffix
        if (!singleMatch(ms, s, p, ep)) {
          if (*ep == '*' || *ep == '?' || *ep == '-') {  // accept empty?
            p = ep + 1;
            goto init;
          }
          s = nullptr;
        } else {
          switch (*ep) {
            case '?': {
              const char* res = match(ms, s + 1, ep + 1);
              if (res != nullptr) {
                s = res;
              } else {
                p = ep + 1;
                goto init;
              }
              break;
            }
            case '+':
              s = maxExpand(ms, s + 1, p, ep);
              break;  // 1 or more repetitions
            case '*':
              s = maxExpand(ms, s, p, ep);
              break;  // 0 or more
            case '-':
              s = minExpand(ms, s, p, ep);
              break;  // 0 or more, shortest
            default:
              s++;
              p = ep;
              goto init;
          }
        }
        break;
      }
    }
  }
  ms->matchDepth++;
  return s;
}

/// Pushes capture i (or the whole match for i == 0 without captures); returns its length or
/// kCapPosition (then the position is on the stack).
ptrdiff_t getOneCapture(MatchState* ms, int i, const char* s, const char* e, const char** cap) {
  if (i >= ms->level) {
    if (i != 0) luaL_error(ms->L, "invalid capture index %%%d", i + 1);
    *cap = s;
    return e - s;
  }
  const ptrdiff_t capl = ms->capture[i].len;
  *cap = ms->capture[i].init;
  if (capl == kCapUnfinished)
    luaL_error(ms->L, "unfinished capture in pattern (a '(' without ')')");
  else if (capl == kCapPosition)
    lua_pushinteger(ms->L, (ms->capture[i].init - ms->srcInit) + 1);
  return capl;
}

void pushOneCapture(MatchState* ms, int i, const char* s, const char* e) {
  const char* cap;
  const ptrdiff_t l = getOneCapture(ms, i, s, e, &cap);
  if (l != kCapPosition) lua_pushlstring(ms->L, cap, size_t(l));
}

int pushCaptures(MatchState* ms, const char* s, const char* e) {
  const int nlevels = (ms->level == 0 && s) ? 1 : ms->level;
  luaL_checkstack(ms->L, nlevels, "too many captures");
  for (int i = 0; i < nlevels; i++) pushOneCapture(ms, i, s, e);
  return nlevels;
}

bool noSpecials(const char* p, size_t l) {
  size_t upto = 0;
  do {
    if (std::strpbrk(p + upto, kSpecials)) return false;
    upto += std::strlen(p + upto) + 1;  // may have more after \0
  } while (upto <= l);
  return true;
}

void prepState(MatchState* ms, lua_State* L, const char* s, size_t ls, const char* p, size_t lp) {
  ms->L = L;
  ms->matchDepth = kMaxCalls;
  ms->srcInit = s;
  ms->srcEnd = s + ls;
  ms->pEnd = p + lp;
  ms->steps = 0;
  ms->level = 0;
}

void reprepState(MatchState* ms) {
  ms->level = 0;
  ms->matchDepth = kMaxCalls;  // also after an error that left a gmatch state mid-way
}

size_t posRelative(lua_Integer pos, size_t len) {
  if (pos > 0) return size_t(pos);
  if (pos == 0) return 1;
  if (pos < -lua_Integer(len)) return 1;
  return len + size_t(pos) + 1;
}

/// Plain search: glibc's memmem is linear in the subject (two-way), so no backtracking here.
const char* memFind(lua_State* L, const char* s1, size_t l1, const char* s2, size_t l2) {
  if (l2 == 0) return s1;
  if (l2 > l1) return nullptr;
  LuaVm::charge(L, int64_t(l1 / 64), "string.find");
  return static_cast<const char*>(memmem(s1, l1, s2, l2));
}

int strFindAux(lua_State* L, bool find) {
  size_t ls, lp;
  const char* s = luaL_checklstring(L, 1, &ls);
  const char* p = luaL_checklstring(L, 2, &lp);
  const size_t init = posRelative(luaL_optinteger(L, 3, 1), ls) - 1;
  if (init > ls) {  // start after the string's end?
    luaL_pushfail(L);
    return 1;
  }
  if (find && (lua_toboolean(L, 4) || noSpecials(p, lp))) {
    const char* s2 = memFind(L, s + init, ls - init, p, lp);
    if (s2) {
      lua_pushinteger(L, (s2 - s) + 1);
      lua_pushinteger(L, lua_Integer((s2 - s) + lp));
      return 2;
    }
  } else {
    MatchState ms;
    const char* s1 = s + init;
    const bool anchor = (*p == '^');
    if (anchor) {
      p++;
      lp--;  // skip anchor character
    }
    prepState(&ms, L, s, ls, p, lp);
    do {
      reprepState(&ms);
      const char* res = match(&ms, s1, p);
      if (res != nullptr) {
        if (find) {
          lua_pushinteger(L, (s1 - s) + 1);  // start
          lua_pushinteger(L, res - s);       // end
          return pushCaptures(&ms, nullptr, nullptr) + 2;
        }
        return pushCaptures(&ms, s1, res);
      }
    } while (s1++ < ms.srcEnd && !anchor);
  }
  luaL_pushfail(L);
  return 1;
}

int strFind(lua_State* L) {
  return strFindAux(L, true);
}
int strMatch(lua_State* L) {
  return strFindAux(L, false);
}

struct GMatchState {
  const char* src;
  const char* p;
  const char* lastMatch;
  MatchState ms;
};

int gmatchAux(lua_State* L) {
  auto* gm = static_cast<GMatchState*>(lua_touserdata(L, lua_upvalueindex(3)));
  gm->ms.L = L;
  for (const char* src = gm->src; src <= gm->ms.srcEnd; src++) {
    reprepState(&gm->ms);
    const char* e = match(&gm->ms, src, gm->p);
    if (e != nullptr && e != gm->lastMatch) {
      gm->src = gm->lastMatch = e;
      return pushCaptures(&gm->ms, src, e);
    }
  }
  return 0;  // not found
}

int gmatch(lua_State* L) {
  size_t ls, lp;
  const char* s = luaL_checklstring(L, 1, &ls);
  const char* p = luaL_checklstring(L, 2, &lp);
  size_t init = posRelative(luaL_optinteger(L, 3, 1), ls) - 1;
  lua_settop(L, 2);  // keep the strings on the closure so they are not collected
  auto* gm = static_cast<GMatchState*>(lua_newuserdatauv(L, sizeof(GMatchState), 0));
  if (init > ls) init = ls + 1;  // start after the string's end
  prepState(&gm->ms, L, s, ls, p, lp);
  gm->src = s + init;
  gm->p = p;
  gm->lastMatch = nullptr;
  lua_pushcclosure(L, gmatchAux, 3);
  return 1;
}

void addS(MatchState* ms, luaL_Buffer* b, const char* s, const char* e) {
  size_t l;
  lua_State* L = ms->L;
  const char* news = lua_tolstring(L, 3, &l);
  const char* p;
  while ((p = static_cast<const char*>(std::memchr(news, kEsc, l))) != nullptr) {
    luaL_addlstring(b, news, size_t(p - news));
    p++;  // skip the escape
    if (*p == kEsc) {
      luaL_addchar(b, *p);
    } else if (*p == '0') {
      luaL_addlstring(b, s, size_t(e - s));
    } else if (std::isdigit(uchar(*p))) {
      const char* cap;
      const ptrdiff_t resl = getOneCapture(ms, *p - '1', s, e, &cap);
      if (resl == kCapPosition)
        luaL_addvalue(b);  // the position is on the stack
      else
        luaL_addlstring(b, cap, size_t(resl));
    } else {
      luaL_error(L, "invalid use of '%c' in replacement string", kEsc);
    }
    l -= size_t(p + 1 - news);
    news = p + 1;
  }
  luaL_addlstring(b, news, l);
  step(ms, int64_t((e - s) / 16));
}

/// Adds the replacement of one match; returns whether the subject changed.
int addValue(MatchState* ms, luaL_Buffer* b, const char* s, const char* e, int tr) {
  lua_State* L = ms->L;
  switch (tr) {
    case LUA_TFUNCTION: {
      lua_pushvalue(L, 3);
      const int n = pushCaptures(ms, s, e);
      lua_call(L, n, 1);
      break;
    }
    case LUA_TTABLE:
      pushOneCapture(ms, 0, s, e);
      lua_gettable(L, 3);
      break;
    default:  // LUA_TNUMBER or LUA_TSTRING
      addS(ms, b, s, e);
      return 1;
  }
  if (!lua_toboolean(L, -1)) {  // nil or false: keep the original text
    lua_pop(L, 1);
    luaL_addlstring(b, s, size_t(e - s));
    return 0;
  }
  if (!lua_isstring(L, -1)) return luaL_error(L, "invalid replacement value (a %s)", luaL_typename(L, -1));
  luaL_addvalue(b);
  return 1;
}

int strGsub(lua_State* L) {
  size_t srcl, lp;
  const char* src = luaL_checklstring(L, 1, &srcl);
  const char* p = luaL_checklstring(L, 2, &lp);
  const char* lastMatch = nullptr;
  const int tr = lua_type(L, 3);
  const lua_Integer maxS = luaL_optinteger(L, 4, lua_Integer(srcl) + 1);
  const bool anchor = (*p == '^');
  lua_Integer n = 0;
  int changed = 0;
  MatchState ms;
  luaL_Buffer b;
  luaL_argexpected(L, tr == LUA_TNUMBER || tr == LUA_TSTRING || tr == LUA_TFUNCTION || tr == LUA_TTABLE, 3,
                   "string/function/table");
  luaL_buffinit(L, &b);
  if (anchor) {
    p++;
    lp--;  // skip anchor character
  }
  prepState(&ms, L, src, srcl, p, lp);
  while (n < maxS) {
    reprepState(&ms);
    const char* e = match(&ms, src, p);
    if (e != nullptr && e != lastMatch) {  // match?
      n++;
      changed = addValue(&ms, &b, src, e, tr) | changed;
      src = lastMatch = e;
    } else if (src < ms.srcEnd) {  // otherwise, skip one character
      luaL_addchar(&b, *src++);
    } else {
      break;  // end of subject
    }
    if (anchor) break;
  }
  if (!changed) {
    lua_pushvalue(L, 1);  // return the original string
  } else {
    luaL_addlstring(&b, src, size_t(ms.srcEnd - src));
    luaL_pushresult(&b);
  }
  lua_pushinteger(L, n);
  return 2;
}

}  // namespace

void openBoundedPatterns(lua_State* L) {
  static const luaL_Reg fns[] = {
      {"find", strFind}, {"match", strMatch}, {"gmatch", gmatch}, {"gsub", strGsub}, {nullptr, nullptr}};
  lua_getglobal(L, "string");  // also the string metatable's __index
  luaL_setfuncs(L, fns, 0);
  lua_pop(L, 1);
}

}  // namespace rm3d
