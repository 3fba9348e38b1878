// Mailbox: delivery at the next step, FIFO, consumption, per-dock reads.
#include "messaging/mailbox.h"

#include <doctest/doctest.h>

using namespace rm3d;

TEST_CASE("pending messages become readable on deliver, oldest first, and reading consumes") {
  Mailbox box;
  for (int i = 0; i < 3; ++i) {
    Message m;
    m.dock = i % 2;
    m.data.type = Value::Type::Integer;
    m.data.integer = i;
    box.pending.push_back(m);
  }
  Message out;
  CHECK_FALSE(box.take(-1, out));
  box.deliver(1);
  CHECK(box.take(1, out));
  CHECK(out.data.integer == 1);
  CHECK(box.take(-1, out));
  CHECK(out.data.integer == 0);
  CHECK(box.take(-1, out));
  CHECK(out.data.integer == 2);
  CHECK_FALSE(box.take(-1, out));
  CHECK(box.received == 3);
}
