// The broadphase's pair cache: Bullet's hashed one, which also keeps each proxy's partners.
//
// Bullet finds the pairs of a body being removed (a dock latching or letting go rebuilds the bodies
// it joins or splits; a world torn down removes them all) by walking every pair in the world, twice:
// once to free their algorithms (cleanProxyFromPairs) and once to remove them
// (removeOverlappingPairsContainingProxy). With 1000 modules docking that was 11% of a step
// (`docking_1000`, 968 latches in 60 steps, each removing two bodies from 6000 pairs). Here each
// proxy's partners are listed as pairs come and go, and a removed proxy's pairs are freed and
// removed in the order Bullet's walk would meet them: the walk takes the pairs in array order, and
// a removed pair's place takes the array's last pair, which is looked at next. So the array of
// pairs (the narrowphase's order, and so the order of the contacts) comes out the same, bit for
// bit.
#pragma once

#include <BulletCollision/BroadphaseCollision/btOverlappingPairCache.h>

#include <unordered_map>
#include <vector>

namespace rm3d {

class PairCache : public btHashedOverlappingPairCache {
 public:
  btBroadphasePair* addOverlappingPair(btBroadphaseProxy* a, btBroadphaseProxy* b) override;
  void* removeOverlappingPair(btBroadphaseProxy* a, btBroadphaseProxy* b, btDispatcher* dispatcher) override;
  void cleanProxyFromPairs(btBroadphaseProxy* proxy, btDispatcher* dispatcher) override;
  void removeOverlappingPairsContainingProxy(btBroadphaseProxy* proxy, btDispatcher* dispatcher) override;
  /// The proxy's partners, in no particular order (tests).
  const std::vector<btBroadphaseProxy*>* partners(btBroadphaseProxy* proxy) const;

 private:
  /// The places in the pair array of the proxy's pairs, in order, into m_places.
  void placesOf(btBroadphaseProxy* proxy);

  std::unordered_map<btBroadphaseProxy*, std::vector<btBroadphaseProxy*>> m_partners;
  std::vector<int> m_places;
};

}  // namespace rm3d
