// Seeded random streams. Every module owns one, derived from the world seed and its module id,
// so adding a module never shifts another module's numbers and runs repeat bit for bit.
#pragma once

#include <cmath>
#include <cstdint>

namespace rm3d {

/// xoshiro256** (Blackman & Vigna), seeded through splitmix64.
class Rng {
 public:
  Rng() { seed(0, 0); }
  Rng(uint64_t seed, uint64_t stream) { this->seed(seed, stream); }

  void seed(uint64_t seed, uint64_t stream) {
    uint64_t x = seed * 0x9E3779B97F4A7C15ull ^ (stream + 0x632BE59BD9B4E019ull) * 0xBF58476D1CE4E5B9ull;
    for (uint64_t& s : m_s) s = splitmix(x);
    m_haveSpare = false;
  }

  uint64_t next() {
    const uint64_t result = rotl(m_s[1] * 5, 7) * 9;
    const uint64_t t = m_s[1] << 17;
    m_s[2] ^= m_s[0];
    m_s[3] ^= m_s[1];
    m_s[1] ^= m_s[2];
    m_s[0] ^= m_s[3];
    m_s[2] ^= t;
    m_s[3] = rotl(m_s[3], 45);
    return result;
  }

  /// Uniform in [0, 1), 53 bits.
  double uniform() { return double(next() >> 11) * 0x1.0p-53; }

  /// Normal deviate (Marsaglia polar method; deterministic, no libm randomness).
  double gaussian(double mu, double sigma) {
    if (m_haveSpare) {
      m_haveSpare = false;
      return mu + sigma * m_spare;
    }
    double u, v, s;
    do {
      u = 2.0 * uniform() - 1.0;
      v = 2.0 * uniform() - 1.0;
      s = u * u + v * v;
    } while (s >= 1.0 || s == 0.0);
    const double f = std::sqrt(-2.0 * std::log(s) / s);
    m_spare = v * f;
    m_haveSpare = true;
    return mu + sigma * u * f;
  }

 private:
  static uint64_t rotl(uint64_t x, int k) { return (x << k) | (x >> (64 - k)); }
  static uint64_t splitmix(uint64_t& x) {
    uint64_t z = (x += 0x9E3779B97F4A7C15ull);
    z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
    z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
    return z ^ (z >> 31);
  }
  uint64_t m_s[4];
  double m_spare = 0;
  bool m_haveSpare = false;
};

}  // namespace rm3d
