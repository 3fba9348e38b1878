// Routing messages over engaged docks through the channel model.
#include "messaging/router.h"

#include <string>
#include <utility>

namespace rm3d {

void Router::route(std::vector<Mailbox>& boxes, std::vector<Module>& modules, int64_t step,
                   size_t mailboxLimit) {
  for (size_t i = 0; i < boxes.size(); ++i) {
    Mailbox& box = boxes[i];
    if (box.outbox.empty()) continue;
    const Module& m = modules[i];
    if (m_channel.rate > 0) m_dockSent.assign(m.docks.size(), 0);
    size_t kept = 0;
    for (size_t k = 0; k < box.outbox.size(); ++k) {
      Message& msg = box.outbox[k];
      const DockState& d = m.docks[size_t(msg.dock)];
      if (!d.engaged) {
        ++box.dropped;
        continue;
      }
      if (m_channel.rate > 0 && m_dockSent[size_t(msg.dock)]++ >= m_channel.rate) {
        // Bandwidth: at most `rate` messages leave a dock per step; the rest wait, in order.
        if (kept != k) box.outbox[kept] = std::move(msg);
        ++kept;
        continue;
      }
      ++box.sent;
      if (m_channel.loss > 0 && m_rng.uniform() < m_channel.loss) {
        ++m_lost;
        continue;
      }
      msg.dock = d.peerDock;
      msg.due = step + 1 + m_channel.delay;
      if (boxes[size_t(d.peerModule)].accept(std::move(msg), mailboxLimit) == Mailbox::Accept::FirstDrop)
        modules[size_t(d.peerModule)].log.push_back(
            "messages dropped: over " + std::to_string(mailboxLimit >> 20) +
            " MiB of unread messages (read them with module.receive)");
    }
    box.outbox.resize(kept);
    box.outboxBytes = 0;
    for (const Message& msg : box.outbox) box.outboxBytes += msg.bytes;
  }
}

MessageStats Router::stats(const std::vector<Mailbox>& boxes) const {
  MessageStats st;
  for (const Mailbox& b : boxes) {
    st.sent += b.sent;
    st.received += b.received;
    st.dropped += b.dropped;
  }
  st.dropped += m_lost;
  return st;
}

}  // namespace rm3d
