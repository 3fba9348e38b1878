// Message routing (docs/architecture.md, the step: 3): each module's outbox goes over its engaged docks into
// the peer's mailbox, readable at the next step (plus the channel's delay), through the channel model (loss,
// delay, rate), seeded and deterministic.
#pragma once

#include <cstddef>
#include <cstdint>
#include <vector>

#include "core/rng.h"
#include "messaging/mailbox.h"
#include "modules/module.h"

namespace rm3d {

/// world.channel{...}: how messages travel over a connection (seeded, deterministic).
struct ChannelDef {
  double loss = 0;          ///< probability that a message is lost
  int delay = 0;            ///< extra steps in flight (a message sent at t is read at t+1+delay)
  int rate = 0;             ///< messages per step per dock (0: unlimited); the rest wait their turn
  size_t maxBytes = 65536;  ///< payload size limit
};

/// Messages counted over a run: sent, delivered (read), lost in flight.
struct MessageStats {
  size_t sent = 0, received = 0, dropped = 0;
};

class Router {
 public:
  void setChannel(const ChannelDef& c) { m_channel = c; }
  const ChannelDef& channel() const { return m_channel; }
  /// Seeds the channel's random stream (losses) from the world seed.
  void seed(uint64_t worldSeed) { m_rng.seed(worldSeed, 0xC4A77E1ull); }
  /// Routes every outbox (in module order) over engaged docks into the peers' mailboxes, due at
  /// step + 1 + delay. A receiver whose unread messages exceed `mailboxLimit` bytes drops what
  /// does not fit, and its log says so once.
  void route(std::vector<Mailbox>& boxes, std::vector<Module>& modules, int64_t step, size_t mailboxLimit);
  MessageStats stats(const std::vector<Mailbox>& boxes) const;

 private:
  ChannelDef m_channel;
  Rng m_rng;
  size_t m_lost = 0;
  std::vector<int> m_dockSent;  ///< per dock, this step (channel rate)
};

}  // namespace rm3d
