// sqrt(x^2 + y^2) without overflow, as glibc's hypot (2.35 and later) computes it, inline: the
// same bits as std::hypot on Debian 12, without a call into libm, which the friction sweep makes
// for every patch in every iteration. Values that are huge, tiny or not finite go to std::hypot.
#pragma once

#include <cmath>

namespace rm3d {

inline double hypotInline(double x, double y) {
  x = std::abs(x);
  y = std::abs(y);
  const double ax = x < y ? y : x, ay = x < y ? x : y;
  if (!std::isfinite(ax) || !std::isfinite(ay) || ax > 0x1p511) return std::hypot(x, y);
  if (ay < 0x1p-459) return ax >= ay / 0x1p-54 ? ax + ay : std::hypot(x, y);
  if (ay <= ax * 0x1p-54) return ax + ay;
  // glibc's kernel without fused multiply-adds: the square root, then one correction step.
  double h = std::sqrt(ax * ax + ay * ay), t1, t2;
  if (h <= 2.0 * ay) {
    const double delta = h - ay;
    t1 = ax * (2.0 * delta - ax);
    t2 = (delta - 2.0 * (ax - ay)) * delta;
  } else {
    const double delta = h - ax;
    t1 = 2.0 * delta * (ax - 2.0 * ay);
    t2 = (4.0 * delta - ay) * ay + delta * delta;
  }
  h -= (t1 + t2) / (2.0 * h);
  return h;
}

}  // namespace rm3d
