// Pace: whether a piece of a step goes to the threads, by the clock. Its choices, fed made-up
// timings: in turn at first, then the faster, the other again every kProbe calls, and back as
// soon as the one taken grows slower; runPaced times what it runs.
#include "core/pace.h"

#include <doctest/doctest.h>

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
  // The threaded calls now take 3 s: their average (1 s) passes the other's 2 s / kSwitch after
  // 8 calls (weight 1/8 a call), and the next call is alone.
  int threaded = 0;
  for (bool h = p.threaded(); h && threaded < 20; h = p.threaded()) {
    ++threaded;
    p.took(h, 3.0);
  }
  CHECK(threaded == 8);
  CHECK_FALSE(p.threaded());
}

TEST_CASE("pace: a way is kept while the other is within kSwitch of it") {
  Pace p;
  // The threads 5% faster: taken after the first calls, and kept; alone 5% faster from then on:
  // still the threads (within the margin) but for the probes.
  run(p, 2 * Pace::kFirst, 1.0, 0.95);
  const int calls = 10 * Pace::kProbe;
  CHECK(run(p, calls, 1.0, 0.95) == calls - 10);
  CHECK(run(p, calls, 0.95, 1.0) == calls - 10);
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
