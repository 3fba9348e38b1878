// A check that PairCache (physics/pair_cache.h) keeps Bullet's pair order, for the unit tests (which
// do not see Bullet's headers).
#pragma once

#include <string>

namespace rm3d {

/// What a random run of pairs added and removed among 60 proxies, with proxies removed as Bullet
/// removes a body's, did: counts of what happened, and the first difference between PairCache and
/// Bullet's own hashed cache (the pair array after each change, the order in which a removed proxy's
/// pairs lose their algorithms, each live proxy's list of partners), empty if none.
struct PairCacheCheck {
  int removedProxies = 0, removedPairs = 0, freed = 0, pairsLeft = 0;
  std::string mismatch;
};
PairCacheCheck checkPairCache(unsigned seed, int rounds);

}  // namespace rm3d
