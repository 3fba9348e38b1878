// The tree solve's node products (node_products.h) give Eigen's bits, built for SSE2 and for AVX;
// and the factor's steps and a hinge's residual there, on AVX, node_eigen.h's (Eigen's).
#include "physics/node_products.h"

#include <doctest/doctest.h>

#include <Eigen/Core>
#include <algorithm>
#include <cmath>
#include <cstring>
#include <random>
#include <vector>

#include "physics/node_eigen.h"

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

namespace {

[[gnu::target("avx")]] void passShareAvx(Mat6& pd, Mat6& g, const Mat6& d, const Mat6& jac, bool joint,
                                         bool axial, bool fresh) {
  rm3d::node_products::passShare(pd.data(), g.data(), d.data(), jac.data(), joint, axial, fresh);
}

[[gnu::target("avx")]] void invertSymmetricAvx(Mat6& a) {
  rm3d::node_products::invertSymmetric(a.data());
}

[[gnu::target("avx")]] Vec6 jointResidualAvx(const Vec6& bias, const Mat6* ja, const Vec6& va, const Mat6* jb,
                                             const Vec6& vb) {
  using rm3d::node_products::V4;
  const double junk = std::nan("");  // (lane 3 is never read)
  Vec6 y;
  rm3d::node_products::jointResidual(y.data(), bias.data(), ja ? ja->data() : nullptr,
                                     V4{va[0], va[1], va[2], junk}, V4{va[3], va[4], va[5], junk},
                                     jb ? jb->data() : nullptr, V4{vb[0], vb[1], vb[2], junk},
                                     V4{vb[3], vb[4], vb[5], junk});
  return y;
}

bool sameBits(const Mat6& a, const Mat6& b) {
  return std::memcmp(a.data(), b.data(), sizeof(Mat6)) == 0;
}

}  // namespace

// Both of a node's factor steps and a hinge's residual, on random blocks over eight orders of magnitude, with
// exact zeros of both signs and denormals among them in half the trials (a product by a zeroed row, or a sum
// in another order, changes such bits).
TEST_CASE(
    "node products: the factor's steps and a hinge's residual on AVX give node_eigen's (Eigen's) bits") {
  if (!__builtin_cpu_supports("avx")) {
    MESSAGE("this CPU has no AVX: the solver takes node_eigen.h's Eigen forms only");
    return;
  }
  std::mt19937_64 rng(11);
  std::normal_distribution<double> normal;
  auto value = [&] { return normal(rng) * std::exp(3 * normal(rng)); };
  auto fill = [&](Mat6& m, bool special) {
    for (int i = 0; i < 36; ++i) {
      const int r = special ? int(rng() % 12) : 12;
      m.data()[i] = r == 0 ? 0.0 : r == 1 ? -0.0 : r == 2 ? 1e-310 * normal(rng) : value();
    }
  };
  int passDiffer = 0, passChanged = 0, invertDiffer = 0, inverted = 0, residualDiffer = 0;
  for (int trial = 0; trial < 4000; ++trial) {
    const bool joint = trial & 1, axial = trial & 2, fresh = trial & 4, special = trial & 8;
    Mat6 d, g, pd, jac;
    fill(d, special), fill(g, special), fill(pd, special), fill(jac, special);
    jac(0, 0) = trial & 16 ? 1 : -1;  // the pivot rows' sign
    Mat6 pd1 = pd, g1 = g, pd2 = pd, g2 = g;
    rm3d::node_eigen::passShare(pd1, g1, d, jac, joint, axial, fresh);
    passShareAvx(pd2, g2, d, jac, joint, axial, fresh);
    passDiffer += !sameBits(pd1, pd2) || !sameBits(g1, g2);
    passChanged += !sameBits(pd1, pd) && (!fresh || !sameBits(g1, g));
    // A pivot: symmetric definite (of either sign, and as a fixed axial row leaves it), or any
    // block (what is read is read the same way).
    Mat6 m;
    fill(m, special);
    Mat6 a = m * m.transpose() + std::exp(3 * normal(rng)) * Mat6::Identity();
    if (trial & 16) a = -a;
    if (trial & 32) {
      a.row(5).setZero(), a.col(5).setZero();
      a(5, 5) = -1;
    }
    if (trial % 7 == 0) a = m;
    Mat6 a1 = a, a2 = a;
    rm3d::node_eigen::invertSymmetric(a1);
    invertSymmetricAvx(a2);
    invertDiffer += !sameBits(a1, a2);
    inverted += !sameBits(a1, a);
    // A hinge's residual, with either body or both.
    Vec6 bias, va, vb;
    for (int i = 0; i < 6; ++i) bias[i] = g(i, 0), va[i] = g(i, 1), vb[i] = g(i, 2);
    const Mat6* ja = trial & 32 ? nullptr : &d;
    const Mat6* jb = trial & 64 ? nullptr : &jac;
    const Vec6 r1 = rm3d::node_eigen::jointResidual(bias, ja, va, jb, vb),
               r2 = jointResidualAvx(bias, ja, va, jb, vb);
    residualDiffer += std::memcmp(r1.data(), r2.data(), sizeof(Vec6)) != 0;
  }
  CHECK(residualDiffer == 0);
  CHECK(passDiffer == 0);
  CHECK(invertDiffer == 0);
  CHECK(passChanged == 4000);  // every pass wrote its parent's pivot (and G where fresh)
  CHECK(inverted == 4000);
}
