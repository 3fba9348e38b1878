// Dock-routed messages. A message sent on a dock in step t is routed over the connection in
// the same step and becomes readable by the receiver at step t+1 (plus the channel's delay).
#pragma once

#include <algorithm>
#include <cstdint>
#include <deque>
#include <vector>

#include "messaging/value.h"

namespace rm3d {

struct Message {
  int dock = -1;    ///< sending dock in an outbox; receiving dock once routed
  double time = 0;  ///< sim time it was sent
  int64_t due = 0;  ///< step at whose start it becomes readable
  Value data;
  size_t bytes = 0;  ///< valueSize(data) (0: not yet sized), counted against the receiver's mailbox limit
};

/// One module's message queues. The outbox is written only by the module's own behaviour
/// (safe to fill from worker threads); pending and inbox are touched only between phases.
struct Mailbox {
  std::vector<Message> outbox;   ///< this step's sends, in order
  size_t outboxBytes = 0;        ///< their size (a module cannot queue more than its peers could hold)
  std::vector<Message> pending;  ///< routed to this module, in flight, in routing order
  std::deque<Message> inbox;     ///< readable now, oldest first
  size_t sent = 0, received = 0, dropped = 0;
  size_t bytes = 0;         ///< unread bytes (pending + inbox)
  bool overflowed = false;  ///< a message was dropped for lack of room (reported once)

  enum class Accept { Ok, Dropped, FirstDrop };
  /// Routes a message towards this module, unless its unread messages would exceed `limit`
  /// bytes (0: no limit): then it is dropped (FirstDrop the first time, to be reported once).
  Accept accept(Message&& msg, size_t limit) {
    if (msg.bytes == 0) msg.bytes = valueSize(msg.data);  // dock:send sized it already
    if (limit && bytes + msg.bytes > limit) {
      ++dropped;
      if (overflowed) return Accept::Dropped;
      overflowed = true;
      return Accept::FirstDrop;
    }
    bytes += msg.bytes;
    pending.push_back(std::move(msg));
    return Accept::Ok;
  }

  /// Step phase 1: messages due by `step` become readable, keeping their order.
  void deliver(int64_t step) {
    if (pending.empty()) return;
    size_t kept = 0;
    for (size_t i = 0; i < pending.size(); ++i) {
      if (pending[i].due <= step) {
        inbox.push_back(std::move(pending[i]));
      } else {
        if (kept != i) pending[kept] = std::move(pending[i]);  // never move onto itself
        ++kept;
      }
    }
    pending.resize(kept);
  }
  /// Oldest message (on `dock`, or on any dock when dock < 0); false when none.
  bool take(int dock, Message& out) {
    for (auto it = inbox.begin(); it != inbox.end(); ++it)
      if (dock < 0 || it->dock == dock) {
        out = std::move(*it);
        inbox.erase(it);
        bytes -= std::min(bytes, out.bytes);
        ++received;
        return true;
      }
    return false;
  }
  /// Drops messages still in flight towards `dock` (its connection is gone); returns how many.
  size_t dropInFlight(int dock) {
    const size_t before = pending.size();
    for (const Message& m : pending)
      if (m.dock == dock) bytes -= std::min(bytes, m.bytes);
    pending.erase(
        std::remove_if(pending.begin(), pending.end(), [dock](const Message& m) { return m.dock == dock; }),
        pending.end());
    dropped += before - pending.size();
    return before - pending.size();
  }
};

}  // namespace rm3d
