// The binding behind world.trace, module.trace and world.metric: argument checks whose errors
// carry the caller's file:line, and the name -> slot cache that keeps the per-step path free of
// C++ name look-ups (a name is checked and given a slot the first time it is seen).
#pragma once

struct lua_State;

namespace rm3d {

struct TraceSeries;

/// fn(name, value) where upvalue 1 of the running C closure is a table name -> slot: records
/// value into `series`. Raises "file:line: fn: ..." on a bad name or value, or too many names.
int recordSeries(lua_State* L, TraceSeries& series, const char* fn, const char* owner);
/// The name at `arg`, checked as a series or metric name (core/trace_series.h).
const char* checkSeriesName(lua_State* L, int arg, const char* fn);
/// The number at `arg`: a finite Lua number (strings are not converted).
double checkSeriesValue(lua_State* L, int arg, const char* fn);
/// Pushes a C closure of f over a new, empty name -> slot table.
void pushSeriesClosure(lua_State* L, int (*f)(lua_State*));

}  // namespace rm3d
