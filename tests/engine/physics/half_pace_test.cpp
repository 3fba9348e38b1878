// HalfPace: whether a long tree's halves go to a second thread, by the clock. Its
// choices, fed made-up timings: in turn at first, then the faster, the other again every kProbe
// calls, and back as soon as the one taken grows slower.
#include "physics/half_pace.h"

#include <doctest/doctest.h>

using Pace = rm3d::HalfPace;

namespace {

/// Runs `calls` calls, each taking `alone` or `helped` seconds by the way chosen; returns how many
/// took the helper.
int run(Pace& p, int calls, double alone, double helped) {
  int n = 0;
  for (int i = 0; i < calls; ++i) {
    const bool h = p.helped();
    n += h;
    p.took(h, h ? helped : alone);
  }
  return n;
}

}  // namespace

TEST_CASE("half pace: both ways in turn first, then the faster, the other once every kProbe calls") {
  Pace p;
  // The first 2 x kFirst calls alternate, the helper first.
  for (int i = 0; i < 2 * Pace::kFirst; ++i) {
    const bool h = p.helped();
    CHECK(h == (i % 2 == 0));
    p.took(h, h ? 2.0 : 1.0);  // the helper slower
  }
  // Then alone, but for one probe of the helper in each kProbe calls.
  const int calls = 10 * Pace::kProbe;
  CHECK(run(p, calls, 1.0, 2.0) == 10);
  // The same with the helper faster: it is taken, alone only on the probes.
  Pace q;
  run(q, 2 * Pace::kFirst, 2.0, 1.0);
  CHECK(run(q, calls, 2.0, 1.0) == calls - 10);
}

TEST_CASE("half pace: the way taken growing slower than the other is left within a few calls") {
  Pace p;
  run(p, 2 * Pace::kFirst + Pace::kProbe, 2.0, 1.0);  // the helper taken
  // The helper's calls now take 3 s: its average passes the other's 2 s after a few calls.
  int helped = 0;
  for (int i = 0; i < 5; ++i) {
    const bool h = p.helped();
    helped += h;
    p.took(h, h ? 3.0 : 2.0);
  }
  CHECK(helped >= 1);
  CHECK(helped <= 4);
  CHECK_FALSE(p.helped());
}
