// The tree solve's node products (node_products.h) give Eigen's bits, built for SSE2 and for AVX.
#include "physics/node_products.h"

#include <doctest/doctest.h>

#include <Eigen/Core>
#include <algorithm>
#include <cmath>
#include <cstring>
#include <random>
#include <vector>

namespace {

using Mat6 = Eigen::Matrix<double, 6, 6>;
using Vec6 = Eigen::Matrix<double, 6, 1>;

struct Node {
  int parent = -1;
  Mat6 dinv, g;
  Vec6 y, x;
};

void passesPlain(std::vector<Node>& nodes, const int* order, int count) {
  rm3d::node_products::downPass(
      nodes.data(), 0, count, order, -1, [](int) {}, [](int) {});
  rm3d::node_products::upPass(
      nodes.data(), 0, count, order, [](int) {}, [](int) {});
}

[[gnu::target("avx")]] void passesAvx(std::vector<Node>& nodes, const int* order, int count) {
  rm3d::node_products::downPass(
      nodes.data(), 0, count, order, -1, [](int) {}, [](int) {});
  rm3d::node_products::upPass(
      nodes.data(), 0, count, order, [](int) {}, [](int) {});
}

/// The same passes in Eigen, as ExactSolver wrote them before.
void passesEigen(std::vector<Node>& nodes) {
  for (int k = int(nodes.size()) - 1; k >= 0; --k) {
    Node& n = nodes[size_t(k)];
    n.x.noalias() = n.dinv * n.y;
    if (n.parent >= 0) nodes[size_t(n.parent)].y.noalias() -= n.g.transpose() * n.y;
  }
  for (Node& n : nodes)
    if (n.parent >= 0) n.x.noalias() -= n.g * nodes[size_t(n.parent)].x;
}

bool sameBits(const std::vector<Node>& a, const std::vector<Node>& b) {
  for (size_t k = 0; k < a.size(); ++k)
    if (std::memcmp(a[k].x.data(), b[k].x.data(), sizeof(Vec6)) != 0 ||
        std::memcmp(a[k].y.data(), b[k].y.data(), sizeof(Vec6)) != 0)
      return false;
  return true;
}

}  // namespace

TEST_CASE("node products: the tree solve's passes give Eigen's bits, with and without AVX") {
  std::mt19937_64 rng(7);
  std::normal_distribution<double> normal;
  // Values over about eight orders of magnitude (three sigma), so that a change of order in a sum
  // shows.
  auto value = [&] { return normal(rng) * std::exp(3 * normal(rng)); };
  const bool avx = __builtin_cpu_supports("avx");
  int plainDiffer = 0, avxDiffer = 0, changed = 0;
  for (int trial = 0; trial < 200; ++trial) {
    // A random tree, children after their parents (as the solver orders its nodes).
    std::vector<Node> tree(size_t(1 + trial % 40));
    for (size_t k = 0; k < tree.size(); ++k) {
      Node& n = tree[k];
      n.parent = k == 0 ? -1 : int(rng() % k);
      for (int i = 0; i < 36; ++i) n.dinv.data()[i] = value(), n.g.data()[i] = value();
      for (int i = 0; i < 6; ++i) n.y[i] = value();
    }
    std::vector<Node> eigen = tree, plain = tree, vec = tree;
    passesEigen(eigen);
    passesPlain(plain, nullptr, int(plain.size()));
    plainDiffer += !sameBits(eigen, plain);
    if (avx) {
      passesAvx(vec, nullptr, int(vec.size()));
      avxDiffer += !sameBits(eigen, vec);
    }
    // The node list (a split tree's lanes): the identity order gives the same.
    std::vector<int> order(tree.size());
    for (size_t k = 0; k < order.size(); ++k) order[k] = int(k);
    std::vector<Node> listed = tree;
    passesPlain(listed, order.data(), int(listed.size()));
    plainDiffer += !sameBits(eigen, listed);
    changed += !sameBits(tree, eigen);
  }
  CHECK(plainDiffer == 0);
  CHECK(avxDiffer == 0);
  if (!avx) MESSAGE("this CPU has no AVX: only the SSE2 build was checked");
  CHECK(changed == 200);  // the passes did write x and y
  // A sum in another order does change the bits of these values (so the checks above can fail).
  int orderMatters = 0;
  for (int t = 0; t < 1000; ++t) {
    const double p = value(), q = value(), s = value();
    orderMatters += ((p + q) + s) != (p + (q + s));
  }
  CHECK(orderMatters > 0);
}

// The passes' hooks, as ExactSolver's iteration uses them: each node's y made by prepare() when the
// down pass first needs it (it starts as NaN, so a use before prepare shows), and its x taken by
// finish() once final. The same bits as making every y first and reading every x after. And each
// node announced by ahead() kAhead nodes before its turn (the solver fetches its rows then).
TEST_CASE("node products: y made on first use and x taken when final give the whole passes' bits") {
  std::mt19937_64 rng(5);
  std::normal_distribution<double> normal;
  for (int trial = 0; trial < 50; ++trial) {
    std::vector<Node> tree(size_t(2 + trial % 30));
    std::vector<Vec6> rhs(tree.size());
    for (size_t k = 0; k < tree.size(); ++k) {
      Node& n = tree[k];
      n.parent = k == 0 ? -1 : int(rng() % k);
      for (int i = 0; i < 36; ++i) n.dinv.data()[i] = normal(rng), n.g.data()[i] = normal(rng);
      for (int i = 0; i < 6; ++i) rhs[k][i] = normal(rng);
    }
    std::vector<Node> whole = tree, hooked = tree;
    for (size_t k = 0; k < tree.size(); ++k) {
      whole[k].y = rhs[k];
      hooked[k].y.setConstant(std::nan(""));
    }
    passesPlain(whole, nullptr, int(whole.size()));
    std::vector<char> made(tree.size(), 0);
    std::vector<Vec6> taken(tree.size(), Vec6::Constant(std::nan("")));
    int prepared = 0;
    std::vector<int> downAhead, upAhead;  // ahead(k)'s nodes, in call order
    rm3d::node_products::downPass(
        hooked.data(), 0, int(hooked.size()), nullptr, -1,
        [&](int k) {
          if (made[size_t(k)]) return;
          made[size_t(k)] = 1;
          ++prepared;
          hooked[size_t(k)].y = rhs[size_t(k)];
        },
        [&](int k) { downAhead.push_back(k); });
    rm3d::node_products::upPass(
        hooked.data(), 0, int(hooked.size()), nullptr, [&](int k) { taken[size_t(k)] = hooked[size_t(k)].x; },
        [&](int k) { upAhead.push_back(k); });
    CHECK(prepared == int(tree.size()));
    // Each node but the first kAhead a pass reaches is announced once, kAhead nodes before its
    // turn: down, the last nodes first; up, the first first.
    const int n = int(tree.size()), ahead = rm3d::node_products::kAhead, announced = std::max(0, n - ahead);
    REQUIRE(int(downAhead.size()) == announced);
    REQUIRE(int(upAhead.size()) == announced);
    for (int i = 0; i < announced; ++i) {
      CHECK(downAhead[size_t(i)] == n - 1 - ahead - i);
      CHECK(upAhead[size_t(i)] == ahead + i);
    }
    int differ = 0;
    for (size_t k = 0; k < tree.size(); ++k)
      differ += std::memcmp(taken[k].data(), whole[k].x.data(), sizeof(Vec6)) != 0;
    CHECK(differ == 0);
  }
}
