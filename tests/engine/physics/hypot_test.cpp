// hypotInline (physics/hypot.h) gives std::hypot's bits: ordinary, huge, tiny and special values.
#include "physics/hypot.h"

#include <doctest/doctest.h>

#include <cstring>
#include <limits>
#include <random>

TEST_CASE("hypotInline gives std::hypot's bits") {
  std::mt19937_64 rng(11);
  std::normal_distribution<double> normal;
  std::uniform_int_distribution<int> exponent(-1100, 1100);
  const double inf = std::numeric_limits<double>::infinity();
  const double special[] = {0.0, -0.0, inf, -inf, std::nan(""), 0x1p511, 0x1p-459, 0x1p-1074};
  auto value = [&](int kind) {
    switch (kind) {
      case 0:
        return normal(rng);
      case 1:
        return std::ldexp(normal(rng), exponent(rng) % 40);  // within a few orders: the kernel
      case 2:
        return std::ldexp(normal(rng), exponent(rng));  // anywhere: scaled and simple paths
      default:
        return special[rng() % 8];
    }
  };
  int differ = 0, kernel = 0;
  for (int i = 0; i < 400000; ++i) {
    const double x = value(int(rng() % 4)), y = value(int(rng() % 4));
    const double want = std::hypot(x, y), got = rm3d::hypotInline(x, y);
    if (std::memcmp(&want, &got, sizeof want) != 0 && !(std::isnan(want) && std::isnan(got))) ++differ;
    // (sqrt(x^2 + y^2) differs from it in some of these: the correction step is not a no-op.)
    kernel += std::isfinite(want) && want != std::sqrt(x * x + y * y);
  }
  CHECK(differ == 0);
  CHECK(kernel > 1000);
}
