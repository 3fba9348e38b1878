// Pace: whether a piece of a step goes to the threads, by the clock. Its choices, fed made-up
// timings: in turn at first, then the faster, the other again every kProbe calls, and back as
// soon as the one taken grows slower, but not for a slow call now and then; runPaced times what
// it runs.
#include "core/pace.h"

#include <doctest/doctest.h>

#include <cstdint>

using Pace = rm3d::Pace;

namespace {

/// Runs `calls` calls, each taking `alone` or `threaded` seconds by the way chosen; returns how
/// many went to the threads.
int run(Pace& p, int calls, double alone, double threaded) {
  int n = 0;
  for (int i = 0; i < calls; ++i) {
    const bool h = p.threaded();
    n += h;
    p.took(h, h ? threaded : alone);
  }
  return n;
}

}  // namespace

TEST_CASE("pace: both ways in turn first, then the faster, the other once every kProbe calls") {
  Pace p;
  // The first 2 x kFirst calls alternate, the threads first.
  for (int i = 0; i < 2 * Pace::kFirst; ++i) {
    const bool h = p.threaded();
    CHECK(h == (i % 2 == 0));
    p.took(h, h ? 2.0 : 1.0);  // the threads slower
  }
  // Then alone, but for one probe of the threads in each kProbe calls.
  const int calls = 10 * Pace::kProbe;
  CHECK(run(p, calls, 1.0, 2.0) == 10);
  // The same with the threads faster: they are taken, alone only on the probes.
  Pace q;
  run(q, 2 * Pace::kFirst, 2.0, 1.0);
  CHECK(run(q, calls, 2.0, 1.0) == calls - 10);
}

TEST_CASE("pace: the way taken growing slower than the other is left within a few calls") {
  Pace p;
  run(p, 2 * Pace::kFirst + Pace::kProbe, 2.0, 1.0);  // the threads taken
  // The threaded calls now take 3 s: the median of their last kWindow calls passes the other's
  // 2 s / kSwitch when more than half of them do (5 calls); the next call is alone.
  int threaded = 0;
  for (bool h = p.threaded(); h && threaded < 40; h = p.threaded()) {
    ++threaded;
    p.took(h, 3.0);
  }
  CHECK(threaded == Pace::kWindow / 2 + 1);
  // From then on alone, but for the threads timed afresh (kFirst calls, every other call) and the
  // probes: still 3 s, so alone is kept.
  CHECK(run(p, 2 * Pace::kProbe, 2.0, 3.0) == Pace::kFirst + 2);
}

TEST_CASE("pace: a slow call now and then does not turn it from the faster way") {
  // Threads 5% faster; one call in 20 of either way (a fixed pseudo-random pick) takes 3 times
  // as long, as when a shared machine deschedules the thread. With an exponential average of
  // about 8 calls and a margin of 10% (the pace before), the first slow threaded call moved their
  // average past alone's over the margin, and the threads, from then on only probed and never 10%
  // faster, were not taken again: 1321 of these 2560 calls went to them (and with alone 5%
  // faster, below, 929 ran alone).
  Pace p;
  uint32_t state = 12345;
  auto slow = [&] {
    state = state * 1664525u + 1013904223u;
    return (state >> 16) % 20 == 0 ? 3.0 : 1.0;
  };
  int threaded = 0;
  const int calls = 40 * Pace::kProbe;
  for (int i = 0; i < calls; ++i) {
    const bool h = p.threaded();
    threaded += h;
    p.took(h, (h ? 1.0 : 1.05) * slow());
  }
  // All but the first alone calls and the probes (one in kProbe).
  CHECK(threaded >= calls - Pace::kFirst - calls / Pace::kProbe);
  // And alone 5% faster, the same.
  Pace q;
  int alone = 0;
  for (int i = 0; i < calls; ++i) {
    const bool h = q.threaded();
    alone += !h;
    q.took(h, (h ? 1.05 : 1.0) * slow());
  }
  CHECK(alone >= calls - Pace::kFirst - calls / Pace::kProbe);
}

TEST_CASE("pace: a way left on calls the machine slowed is taken again within a few calls") {
  Pace p;
  run(p, 2 * Pace::kFirst + 100, 1.2, 1.0);  // the threads taken, 1.0 s against 1.2
  // Five threaded calls in a row slowed to 3 s (more than half its window): alone is taken.
  for (int i = 0; i < Pace::kWindow / 2 + 1; ++i) {
    REQUIRE(p.threaded());
    p.took(true, 3.0);
  }
  CHECK_FALSE(p.threaded());
  p.took(false, 1.2);
  // The threads, timed afresh every other call, are back at 1.0 s: taken again after kFirst of
  // them (a probe once in kProbe calls would have needed five, some 300 calls).
  const int calls = 2 * Pace::kProbe;
  CHECK(run(p, calls, 1.2, 1.0) >= calls - 2 * Pace::kFirst - 2);
}

TEST_CASE("pace: a way is kept while the other is within kSwitch of it") {
  Pace p;
  // The threads 1% faster: taken after the first calls, and kept; alone 1% faster from then on:
  // still the threads (within the margin) but for the probes.
  run(p, 2 * Pace::kFirst, 1.0, 0.99);
  const int calls = 10 * Pace::kProbe;
  CHECK(run(p, calls, 1.0, 0.99) == calls - 10);
  CHECK(run(p, calls, 0.99, 1.0) == calls - 10);
  // Alone 20% faster: left.
  CHECK(run(p, calls, 0.8, 1.0) < calls / 2);
}

TEST_CASE("pace: runPaced runs the way the pace says, or the threads always, and times it") {
  Pace p;
  int threads = 0, alone = 0;
  auto paced = [&](bool always) {
    return rm3d::runPaced(
        p, always, [&] { ++threads; }, [&] { ++alone; });
  };
  // First call: the threads (in turn, threads first). Its turn is then alone, but `always`
  // takes the threads; without it, alone.
  CHECK(paced(false));
  CHECK(paced(true));
  CHECK(threads == 2);
  CHECK(alone == 0);
  CHECK_FALSE(paced(false));
  CHECK(threads == 2);
  CHECK(alone == 1);
}
