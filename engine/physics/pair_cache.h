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

#include <cstdint>
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

  // Each proxy's partners: a list of m_lists, found through an open-addressed table on the
  // proxy's address (linear probing, at most half full; a removed proxy's entry closes the gap
  // behind it). A list let go is kept, emptied, for the next proxy. (A node-based hash map cost a
  // cache miss or two and a division for each pair made or removed: about 1500 a step with 1000
  // modules, on the main thread.)
  struct Entry {
    btBroadphaseProxy* proxy = nullptr;  // null: empty
    int list = -1;
  };
  size_t home(const btBroadphaseProxy* proxy) const {
    return size_t((uint64_t(reinterpret_cast<uintptr_t>(proxy)) * 0x9E3779B97F4A7C15ull) >> m_shift);
  }
  /// Where the proxy's entry is, or the empty entry where it would go.
  size_t probe(const btBroadphaseProxy* proxy) const;
  /// The proxy's list, made (empty) if it has none.
  std::vector<btBroadphaseProxy*>& listOf(btBroadphaseProxy* proxy);
  void forget(btBroadphaseProxy* proxy);
  std::vector<Entry> m_table;
  int m_shift = 64, m_entries = 0;
  std::vector<std::vector<btBroadphaseProxy*>> m_lists;
  std::vector<int> m_freeLists;
  std::vector<int> m_places;
};

}  // namespace rm3d
