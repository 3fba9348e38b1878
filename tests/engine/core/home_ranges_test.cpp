// HomeRanges: every item is taken exactly once, each task starts on its own range, and a task
// whose thread never comes leaves its items to the others.
#include "core/home_ranges.h"

#include <doctest/doctest.h>

#include <atomic>
#include <thread>
#include <utility>
#include <vector>

namespace {

// Runs the tasks in the given order on this thread, one after the other; returns each item's taker
// (-1: none) and each task's first chunk's start (-1: it took none).
std::pair<std::vector<int>, std::vector<int>> runInOrder(int n, int tasks, int chunk,
                                                         const std::vector<int>& order) {
  rm3d::HomeRanges homes;
  homes.begin(n, tasks, chunk);
  std::vector<int> taker(size_t(n), -1), first(size_t(tasks), -1);
  for (int t : order)
    homes.run(t, [&](int b, int e) {
      CHECK(b < e);
      CHECK(e - b <= chunk);
      if (first[size_t(t)] < 0) first[size_t(t)] = b;
      for (int i = b; i < e; ++i) {
        CHECK(taker[size_t(i)] == -1);
        taker[size_t(i)] = t;
      }
    });
  return {taker, first};
}

}  // namespace

TEST_CASE("each task starts on its own range, then takes what is left of the others' in turn") {
  // Task 3 takes its first chunk; while it holds it, task 1 runs (a second thread, here nested):
  // its own range first, then 2's, then the rest of 3's, then 0's; task 3 then finds nothing left.
  rm3d::HomeRanges homes;
  homes.begin(1000, 4, 50);
  std::vector<std::pair<int, int>> chunks;  // (task, start)
  bool nested = false;
  homes.run(3, [&](int b, int) {
    chunks.push_back({3, b});
    if (nested) return;
    nested = true;
    homes.run(1, [&](int b1, int) { chunks.push_back({1, b1}); });
  });
  std::vector<std::pair<int, int>> expect{{3, 750}};
  for (int b : {250, 300, 350, 400, 450, 500, 550, 600, 650, 700, 800, 850, 900, 950, 0, 50, 100, 150, 200})
    expect.push_back({1, b});
  CHECK(chunks == expect);
}

TEST_CASE("with no more items than tasks, item i is task i's") {
  for (int n : {1, 2, 3, 4}) {
    for (int t = 0; t < 4; ++t) {
      // Task t comes first: it takes its own item, or (none of its own) the first other in turn.
      rm3d::HomeRanges homes;
      homes.begin(n, 4, 1);
      int first = -1;
      homes.run(t, [&](int b, int) {
        if (first < 0) first = b;
      });
      CHECK(first == (t < n ? t : 0));
    }
  }
}

TEST_CASE("a task whose thread never comes leaves nothing undone") {
  for (int tasks : {1, 2, 3, 8}) {
    for (int n : {0, 1, 7, 64, 1001}) {
      const auto [taker, first] = runInOrder(n, tasks, 5, {0});
      for (int t : taker) CHECK(t == 0);
      CHECK(first[0] == (n > 0 ? 0 : -1));
    }
  }
}

TEST_CASE("on threads, every item is taken exactly once, run after run") {
  rm3d::HomeRanges homes;
  const int n = 5000, tasks = 4;
  std::vector<std::atomic<int>> hits(n);
  for (int round = 0; round < 20; ++round) {
    homes.begin(n, tasks, 16);
    std::vector<std::thread> threads;
    for (int t = 0; t < tasks; ++t)
      threads.emplace_back([&, t] {
        homes.run(t, [&](int b, int e) {
          for (int i = b; i < e; ++i) hits[size_t(i)]++;
        });
      });
    for (auto& th : threads) th.join();
  }
  for (auto& h : hits) CHECK(h.load() == 20);
}
