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

TEST_CASE("a run of one task a thread runs each once, with fewer tasks than threads too") {
  for (int threads : {2, 3, 4}) {
    rm3d::BehaviourPool pool(threads);
    for (int n = 1; n <= threads; ++n) {
      std::vector<std::atomic<int>> hits(static_cast<size_t>(n));
      for (int round = 0; round < 200; ++round)
        pool.run(
            n, [&](int i) { hits[size_t(i)]++; }, 1);
      for (auto& h : hits) CHECK(h.load() == 200);
    }
  }
}
