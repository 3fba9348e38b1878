// Dock-routed messages. A message sent on a dock in step t is routed over the connection in
// the same step and delivered into the receiver's mailbox at the start of step t+1.
#pragma once

#include <deque>
#include <vector>

#include "script/lua_value.h"

namespace rm3d {

struct Message {
  int dock = -1;     ///< receiving dock (index in the receiver's type)
  double time = 0;   ///< sim time it was sent
  LuaValue data;
};

/// One module's message queues. The outbox is written only by the module's own behaviour
/// (safe to fill from worker threads); inbox and pending are touched only between phases.
struct Mailbox {
  std::vector<Message> outbox;  ///< dock = sending dock
  std::vector<Message> pending; ///< routed to this module, visible next step
  std::deque<Message> inbox;    ///< readable now, oldest first
  size_t sent = 0, received = 0, dropped = 0;

  /// Step phase 1: what was routed last step becomes readable.
  void deliver() {
    for (Message& m : pending) inbox.push_back(std::move(m));
    pending.clear();
  }
  /// Oldest message (on `dock`, or on any dock when dock < 0); false when none.
  bool take(int dock, Message& out) {
    for (auto it = inbox.begin(); it != inbox.end(); ++it)
      if (dock < 0 || it->dock == dock) {
        out = std::move(*it);
        inbox.erase(it);
        ++received;
        return true;
      }
    return false;
  }
};

}  // namespace rm3d
