// The pair cache with each proxy's partners (physics/pair_cache.h) against Bullet's own: the same
// pair array, in the same order, after pairs come and go and proxies are removed; and a removed
// proxy's pairs freed in the order Bullet's walk frees them.
#include <doctest/doctest.h>

#include "physics/pair_cache_check.h"

TEST_CASE(
    "pair cache: the same pairs in the same order as Bullet's, through adds, removals and removed proxies") {
  for (unsigned seed : {11u, 12u, 13u}) {
    INFO("seed " << seed);
    const rm3d::PairCacheCheck c = rm3d::checkPairCache(seed, 4000);
    CHECK(c.mismatch == "");
    // The rounds did what they are for: many pairs, proxies with many partners removed.
    CHECK(c.removedProxies >= 20);
    CHECK(c.removedPairs >= 300);
    CHECK(c.freed >= 300);
    CHECK(c.pairsLeft >= 30);
  }
}
