// BehaviourPool: every index runs exactly once, whatever the thread count.
#include "world/behaviour_pool.h"

#include <doctest/doctest.h>

#include <atomic>
#include <vector>

TEST_CASE("each index runs once with 1, 2 and 4 threads, many times over") {
  for (int threads : {1, 2, 4}) {
    rm3d::BehaviourPool pool(threads);
    std::vector<std::atomic<int>> hits(1000);
    for (int round = 0; round < 50; ++round) pool.run(1000, [&](int i) { hits[size_t(i)]++; });
    for (auto& h : hits) CHECK(h.load() == 50);
  }
}
