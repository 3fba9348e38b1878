// Rng: repeatable streams, independent per module id, sane statistics.
#include "core/rng.h"

#include <doctest/doctest.h>

#include <cmath>

using rm3d::Rng;

TEST_CASE("the same seed and stream repeat; another stream differs") {
  Rng a(42, 3), b(42, 3), c(42, 4);
  bool differs = false;
  for (int i = 0; i < 100; ++i) {
    const uint64_t x = a.next();
    CHECK(x == b.next());
    differs |= x != c.next();
  }
  CHECK(differs);
}

TEST_CASE("uniform and gaussian have the right mean and spread") {
  Rng r(7, 1);
  const int n = 200000;
  double su = 0, sg = 0, sg2 = 0;
  for (int i = 0; i < n; ++i) {
    const double u = r.uniform();
    CHECK((u >= 0.0 && u < 1.0));
    su += u;
    const double g = r.gaussian(2.0, 0.5);
    sg += g;
    sg2 += g * g;
  }
  CHECK(su / n == doctest::Approx(0.5).epsilon(0.01));
  const double mean = sg / n;
  CHECK(mean == doctest::Approx(2.0).epsilon(0.01));
  CHECK(std::sqrt(sg2 / n - mean * mean) == doctest::Approx(0.5).epsilon(0.01));
}
