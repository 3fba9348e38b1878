// The broadphase's pair cache with each proxy's partners (physics/pair_cache.h).
#include "physics/pair_cache.h"

#include <algorithm>
#include <random>
#include <string>
#include <utility>

#include "physics/pair_cache_check.h"

namespace rm3d {

btBroadphasePair* PairCache::addOverlappingPair(btBroadphaseProxy* a, btBroadphaseProxy* b) {
  const int before = getNumOverlappingPairs();
  btBroadphasePair* pair = btHashedOverlappingPairCache::addOverlappingPair(a, b);
  if (getNumOverlappingPairs() != before) {  // a new pair (not one already there, nor one filtered out)
    listOf(a).push_back(b);                  // (one at a time: making b's list may move a's)
    listOf(b).push_back(a);
  }
  return pair;
}

void* PairCache::removeOverlappingPair(btBroadphaseProxy* a, btBroadphaseProxy* b, btDispatcher* dispatcher) {
  const int before = getNumOverlappingPairs();
  void* user = btHashedOverlappingPairCache::removeOverlappingPair(a, b, dispatcher);
  if (getNumOverlappingPairs() != before)
    for (auto [p, q] : {std::pair{a, b}, std::pair{b, a}}) {
      std::vector<btBroadphaseProxy*>& list = listOf(p);
      const auto at = std::find(list.begin(), list.end(), q);
      *at = list.back();
      list.pop_back();
    }
  return user;
}

size_t PairCache::probe(const btBroadphaseProxy* proxy) const {
  const size_t mask = m_table.size() - 1;
  size_t i = home(proxy);
  while (m_table[i].proxy && m_table[i].proxy != proxy) i = (i + 1) & mask;
  return i;
}

std::vector<btBroadphaseProxy*>& PairCache::listOf(btBroadphaseProxy* proxy) {
  if (2 * (m_entries + 1) > int(m_table.size())) {  // at most half full: twice the size
    std::vector<Entry> old(std::max<size_t>(64, 2 * m_table.size()));
    old.swap(m_table);
    m_shift = 64 - __builtin_ctzll(m_table.size());
    for (const Entry& e : old)
      if (e.proxy) m_table[probe(e.proxy)] = e;
  }
  Entry& e = m_table[probe(proxy)];
  if (!e.proxy) {
    e.proxy = proxy;
    if (m_freeLists.empty()) {
      e.list = int(m_lists.size());
      m_lists.emplace_back();
    } else {
      e.list = m_freeLists.back();
      m_freeLists.pop_back();
    }
    ++m_entries;
  }
  return m_lists[size_t(e.list)];
}

void PairCache::forget(btBroadphaseProxy* proxy) {
  if (m_table.empty()) return;
  size_t i = probe(proxy);
  if (!m_table[i].proxy) return;
  m_lists[size_t(m_table[i].list)].clear();
  m_freeLists.push_back(m_table[i].list);
  --m_entries;
  // The entries after it in its run that would no longer be found move back into the gap.
  const size_t mask = m_table.size() - 1;
  for (size_t j = (i + 1) & mask; m_table[j].proxy; j = (j + 1) & mask) {
    const size_t k = home(m_table[j].proxy);
    // k lies cyclically in (i, j]: the entry is found from its home without passing i.
    if (((j - k) & mask) < ((j - i) & mask)) continue;
    m_table[i] = m_table[j];
    i = j;
  }
  m_table[i] = Entry{};
}

const std::vector<btBroadphaseProxy*>* PairCache::partners(btBroadphaseProxy* proxy) const {
  if (m_table.empty()) return nullptr;
  const Entry& e = m_table[probe(proxy)];
  return e.proxy ? &m_lists[size_t(e.list)] : nullptr;
}

void PairCache::placesOf(btBroadphaseProxy* proxy) {
  m_places.clear();
  const std::vector<btBroadphaseProxy*>* list = partners(proxy);
  if (!list) return;
  const btBroadphasePair* first = getOverlappingPairArrayPtr();
  for (btBroadphaseProxy* q : *list) m_places.push_back(int(findPair(proxy, q) - first));
  std::sort(m_places.begin(), m_places.end());
}

void PairCache::cleanProxyFromPairs(btBroadphaseProxy* proxy, btDispatcher* dispatcher) {
  // As Bullet's walk: each pair holding the proxy, in array order, loses its algorithm (which may
  // let go of contact manifolds: the order they go in is the order of the ones left).
  placesOf(proxy);
  for (int i : m_places) cleanOverlappingPair(getOverlappingPairArray()[i], dispatcher);
}

void PairCache::removeOverlappingPairsContainingProxy(btBroadphaseProxy* proxy, btDispatcher* dispatcher) {
  // As Bullet's walk: in array order, each pair holding the proxy is removed and the last pair
  // takes its place; if that one holds the proxy too (it is then the last of m_places), the same
  // place is taken again.
  placesOf(proxy);
  for (size_t k = 0; k < m_places.size();) {
    const int i = m_places[k];
    const int last = getNumOverlappingPairs() - 1;
    const btBroadphasePair& pair = getOverlappingPairArray()[i];
    removeOverlappingPair(pair.m_pProxy0, pair.m_pProxy1, dispatcher);
    if (i != last && m_places.back() == last) {
      m_places.pop_back();  // that pair now lies at i
    } else {
      ++k;
    }
  }
  forget(proxy);  // (it is going away; its address may serve a new proxy)
}

}  // namespace rm3d

// --- the unit tests' check (physics/pair_cache_check.h) ---

namespace rm3d {

namespace {

using Trace = std::vector<std::pair<int, int>>;

/// Records the pairs whose algorithms are freed, in order (by the proxies' ids).
template <class Base>
struct Recording : Base {
  Trace freed;
  void cleanOverlappingPair(btBroadphasePair& pair, btDispatcher* dispatcher) override {
    freed.emplace_back(pair.m_pProxy0->m_uniqueId, pair.m_pProxy1->m_uniqueId);
    Base::cleanOverlappingPair(pair, dispatcher);
  }
};

Trace pairsOf(btOverlappingPairCache& c) {
  Trace out;
  const btBroadphasePairArray& a = c.getOverlappingPairArray();
  for (int i = 0; i < a.size(); ++i) out.emplace_back(a[i].m_pProxy0->m_uniqueId, a[i].m_pProxy1->m_uniqueId);
  return out;
}

}  // namespace

PairCacheCheck checkPairCache(unsigned seed, int rounds) {
  constexpr int kProxies = 60;
  std::vector<btBroadphaseProxy> proxies(kProxies);
  for (int i = 0; i < kProxies; ++i) {
    proxies[size_t(i)].m_uniqueId = i + 1;
    proxies[size_t(i)].m_collisionFilterGroup = proxies[size_t(i)].m_collisionFilterMask = -1;
  }
  Recording<PairCache> ours;
  Recording<btHashedOverlappingPairCache> bullets;
  std::mt19937 rng(seed);
  std::vector<int> alive(kProxies);
  for (int i = 0; i < kProxies; ++i) alive[size_t(i)] = i;
  PairCacheCheck out;
  for (int round = 0; round < rounds && alive.size() > 2 && out.mismatch.empty(); ++round) {
    const unsigned op = rng() % 100;
    btBroadphaseProxy* a = &proxies[size_t(alive[rng() % alive.size()])];
    btBroadphaseProxy* b = &proxies[size_t(alive[rng() % alive.size()])];
    if (op < 1) {
      // A proxy goes away, as btCollisionWorld::removeCollisionObject and destroyProxy take it.
      ours.cleanProxyFromPairs(a, nullptr);
      bullets.cleanProxyFromPairs(a, nullptr);
      ours.removeOverlappingPairsContainingProxy(a, nullptr);
      bullets.removeOverlappingPairsContainingProxy(a, nullptr);
      alive.erase(std::find(alive.begin(), alive.end(), int(a - proxies.data())));
      ++out.removedProxies;
    } else if (a != b && op < 65) {
      ours.addOverlappingPair(a, b);
      bullets.addOverlappingPair(a, b);
    } else if (a != b) {
      out.removedPairs += bullets.findPair(a, b) != nullptr;
      ours.removeOverlappingPair(a, b, nullptr);
      bullets.removeOverlappingPair(a, b, nullptr);
    }
    if (pairsOf(ours) != pairsOf(bullets))
      out.mismatch = "the pair arrays differ after round " + std::to_string(round);
    else if (ours.freed != bullets.freed)
      out.mismatch = "the pairs were freed in another order by round " + std::to_string(round);
  }
  out.freed = int(ours.freed.size());
  out.pairsLeft = ours.getNumOverlappingPairs();
  const Trace left = pairsOf(ours);
  for (int i : alive) {
    const std::vector<btBroadphaseProxy*>* list = ours.partners(&proxies[size_t(i)]);
    int count = 0;
    for (const auto& [p, q] : left) count += p == i + 1 || q == i + 1;
    if (out.mismatch.empty() && (list ? int(list->size()) : 0) != count)
      out.mismatch = "proxy " + std::to_string(i + 1) + " lists " + std::to_string(list ? list->size() : 0) +
                     " partners, not " + std::to_string(count);
  }
  return out;
}

}  // namespace rm3d
