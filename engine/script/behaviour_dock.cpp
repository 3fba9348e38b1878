// Behaviour side: the Dock type (module.dock(name) -> userdata {index}): state queries,
// enable/disable, send, peer.
#include <lua.hpp>

#include "script/behaviour.h"
#include "script/behaviour_bindings.h"
#include "script/lua_value.h"
#include "script/lua_vm.h"
#include "world/world.h"

namespace rm3d {

namespace {

constexpr const char* kDockMeta = "rm3d.Dock";

struct DockUd {
  int index;
};

int checkDock(lua_State* L) {
  return checkIndexUserdata(L, behaviourContext(L).dockMeta, kDockMeta);
}

const DockState& dockState(lua_State* L, int d) {
  return behaviourContext(L).module.self().docks[size_t(d)];
}

/// Queues dock:enable()/disable(): dock states are frozen while behaviours run (other modules
/// read them in parallel); the world applies the request after the phase, in module order.
void requestDock(lua_State* L, int d, bool enable) {
  Module& m = behaviourContext(L).module.self();
  m.dockRequests[size_t(d)] = enable ? 1 : 0;
  m.hasDockRequests = true;
}

/// dock:enabled() -> bool (willing to connect; a request made this step counts already)
int dockEnabled(lua_State* L) {
  const int d = checkDock(L);
  const int8_t request = behaviourContext(L).module.self().dockRequests[size_t(d)];
  lua_pushboolean(L, request >= 0 ? request != 0 : dockState(L, d).enabled);
  return 1;
}

/// dock:engaged() -> bool (connected)
int dockEngaged(lua_State* L) {
  lua_pushboolean(L, dockState(L, checkDock(L)).engaged);
  return 1;
}

/// dock:gender() -> "none" | "male" | "female"
int dockGender(lua_State* L) {
  const int d = checkDock(L);
  const BehaviourContext& c = behaviourContext(L);
  lua_pushstring(L, genderName(c.module.self().type->docks[size_t(d)].gender));
  return 1;
}

/// dock:enable(): willing to connect
int dockEnable(lua_State* L) {
  requestDock(L, checkDock(L), true);
  return 0;
}

/// dock:disable(): unwilling; an engaged connection here is released this step
int dockDisable(lua_State* L) {
  requestDock(L, checkDock(L), false);
  return 0;
}

/// dock:name() -> string
int dockName(lua_State* L) {
  const int d = checkDock(L);
  const BehaviourContext& c = behaviourContext(L);
  lua_pushstring(L, c.module.self().type->docks[size_t(d)].name.c_str());
  return 1;
}

/// dock:send(value) -> bool: queue a plain Lua value (<= the channel's max_bytes, 64 KiB by default)
/// for the module docked here;
/// it can read it next step. False when nothing is engaged here, or when this step's sends already
/// fill the mailbox limit (RunOptions::mailboxLimit, 8 MiB: no receiver could hold more).
int dockSend(lua_State* L) {
  const int d = checkDock(L);
  luaL_checkany(L, 2);
  const BehaviourContext& c = behaviourContext(L);
  Mailbox& box = c.module.mailbox();
  const size_t limit = c.module.world().options().mailboxLimit;
  if (!c.module.self().docks[size_t(d)].engaged || (limit && box.outboxBytes >= limit)) {
    if (c.module.self().docks[size_t(d)].engaged) ++box.dropped;
    lua_pushboolean(L, 0);
    return 1;
  }
  bool ok;
  {
    std::string err;
    Message msg;
    msg.dock = d;
    msg.time = c.module.world().time();
    ok = readLuaValue(L, 2, msg.data, c.module.world().channel().maxBytes, err);
    if (ok) {
      msg.bytes = valueSize(msg.data);
      box.outboxBytes += msg.bytes;
      box.outbox.push_back(std::move(msg));
    } else
      lua_pushfstring(L, "dock:send: %s", err.c_str());
  }
  if (!ok) {
    luaL_where(L, 1);
    lua_insert(L, -2);
    lua_concat(L, 2);
    return lua_error(L);
  }
  lua_pushboolean(L, 1);
  return 1;
}

/// dock:peer() -> module id, dock name of the engaged peer, or nil
int dockPeer(lua_State* L) {
  const int d = checkDock(L);
  const BehaviourContext& c = behaviourContext(L);
  const DockState& s = c.module.self().docks[size_t(d)];
  if (!s.engaged) return 0;
  const Module& peer = c.module.world().module(s.peerModule);
  lua_pushinteger(L, peer.id);
  lua_pushstring(L, peer.type->docks[size_t(s.peerDock)].name.c_str());
  return 2;
}

int dockToString(lua_State* L) {
  const int d = checkDock(L);
  const BehaviourContext& c = behaviourContext(L);
  lua_pushfstring(L, "Dock(%s)", c.module.self().type->docks[size_t(d)].name.c_str());
  return 1;
}

}  // namespace

void openDockType(lua_State* L) {
  static const luaL_Reg methods[] = {
      {"enabled", dockEnabled}, {"engaged", dockEngaged}, {"gender", dockGender},
      {"enable", dockEnable},   {"disable", dockDisable}, {"send", dockSend},
      {"name", dockName},       {"peer", dockPeer},       {nullptr, nullptr}};
  luaL_newmetatable(L, kDockMeta);
  sealMetatable(L);
  behaviourContext(L).dockMeta = lua_topointer(L, -1);
  luaL_newlib(L, methods);
  lua_setfield(L, -2, "__index");
  lua_pushcfunction(L, dockToString);
  lua_setfield(L, -2, "__tostring");
  lua_pop(L, 1);
}

void pushDock(lua_State* L, int index) {
  auto* ud = static_cast<DockUd*>(lua_newuserdatauv(L, sizeof(DockUd), 0));
  ud->index = index;
  luaL_setmetatable(L, kDockMeta);
}

}  // namespace rm3d
