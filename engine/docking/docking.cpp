// Docking: initial connections, the magnet and latching, undocking and breakage.
#include "docking/docking.h"

#include <algorithm>
#include <cmath>
#include <string>
#include <string_view>

#include "core/error.h"
#include "docking/dock_frame.h"
#include "physics/bullet_layout.h"

namespace rm3d {

namespace {

// Work handed to the threads in blocks of this many modules (finding those with a free dock;
// posing their free docks), free docks (finding their pairs) or connections (their loads).
constexpr int kModuleBlock = 128;
constexpr int kBoxBlock = 64;
constexpr int kDockBlock = 128;
constexpr int kLoadBlock = 32;

Eigen::Vector3i cellOf(const Vec3& p, double cell) {
  return Eigen::Vector3i(int(std::floor(p.x() / cell)), int(std::floor(p.y() / cell)),
                         int(std::floor(p.z() / cell)));
}

/// A cell's key is its three coordinates' keys, each by its axis's multiplier, combined by xor.
constexpr uint64_t kAxisKey[3] = {73856093ull, 19349663ull, 83492791ull};
uint64_t axisKey(int v, int axis) {
  return uint64_t(uint32_t(v)) * kAxisKey[axis];
}
uint64_t cellKey(const Eigen::Vector3i& c) {
  return axisKey(c.x(), 0) ^ axisKey(c.y(), 1) ^ axisKey(c.z(), 2);
}

/// The slot of the dock hash that holds cell key k, or the free slot where it would go.
size_t cellSlot(const std::vector<uint64_t>& keys, const std::vector<int>& head, uint64_t k) {
  const size_t mask = head.size() - 1;
  size_t h = size_t((k * 0x9E3779B97F4A7C15ull) >> 20) & mask;
  while (head[h] >= 0 && keys[h] != k) h = (h + 1) & mask;
  return h;
}

/// Cell key k's bit in a filter of `bits` bits (a power of two): clear, the cell holds no dock.
size_t cellBit(uint64_t k, size_t bits) {
  return size_t((k * 0xD6E8FEB86659FD93ull) >> 32) & (bits - 1);
}
bool cellMayHold(const std::vector<uint64_t>& filter, uint64_t k) {
  const size_t b = cellBit(k, filter.size() * 64);
  return (filter[b >> 6] >> (b & 63)) & 1;
}

}  // namespace

std::vector<int> componentOf(const std::vector<Module>& modules, int m) {
  std::vector<int> out{m};
  std::vector<char> seen(modules.size(), 0);
  seen[size_t(m)] = 1;
  for (size_t k = 0; k < out.size(); ++k)
    for (const DockState& d : modules[size_t(out[k])].docks)
      if (d.engaged && !seen[size_t(d.peerModule)]) {
        seen[size_t(d.peerModule)] = 1;
        out.push_back(d.peerModule);
      }
  return out;
}

void Docking::connect(const DockingScene& s, int a, int da, int b, int db, int orientation) {
  if (a == b) throw InputError("a module cannot dock to itself");
  Module& ma = s.modules[size_t(a)];
  Module& mb = s.modules[size_t(b)];
  const DockDef& defA = ma.type->docks[size_t(da)];
  const DockDef& defB = mb.type->docks[size_t(db)];
  for (auto [m, d] : {std::pair<Module*, int>{&ma, da}, std::pair<Module*, int>{&mb, db}})
    if (m->docks[size_t(d)].engaged)
      throw InputError("dock '" + m->type->docks[size_t(d)].name + "' of " + m->name + " is already engaged");
  if (!gendersMate(defA.gender, defB.gender))
    throw InputError(std::string("a ") + genderName(defA.gender) + " dock cannot mate with a " +
                     genderName(defB.gender) + " dock");
  const int sym = std::max(1, std::min(defA.symmetry, defB.symmetry));
  if (orientation < 0 || orientation >= sym)
    throw InputError("orientation must be 0.." + std::to_string(sym - 1) + ", got " +
                     std::to_string(orientation));
  const std::vector<int> comp = componentOf(s.modules, b);
  const DockError e =
      dockError(dockPose(s.physics, s.modules[size_t(a)], da), dockPose(s.physics, s.modules[size_t(b)], db));
  const bool facing = e.gap <= 0.001 && e.angle <= 1.0 / kDegPerRad;
  if (std::find(comp.begin(), comp.end(), a) != comp.end() && !facing) {
    // Closing a loop: both docks are placed already; they must face each other.
    throw InputError(ma.name + " and " + mb.name +
                     " are already connected another way and these docks do not face each other (gap " +
                     std::to_string(e.gap * 1000) + " mm, angle " + std::to_string(e.angle * kDegPerRad) +
                     " deg; at most 1 mm and 1 deg)");
  }
  // Docks that already face each other are locked where they are (closing a loop, or modules
  // placed by hand); otherwise b's side is moved so the faces mate exactly.
  lock(s, a, da, b, db, orientation, !facing);
}

void Docking::lock(const DockingScene& s, int a, int da, int b, int db, int orientation, bool snap,
                   bool split) {
  Module& ma = s.modules[size_t(a)];
  Module& mb = s.modules[size_t(b)];
  const DockDef& defA = ma.type->docks[size_t(da)];
  const DockDef& defB = mb.type->docks[size_t(db)];
  if (snap) {
    // Move the side that is free to move (not holding a fixed module, not already joined to
    // the other) so the two faces mate exactly.
    std::vector<int> compB = componentOf(s.modules, b), compA = componentOf(s.modules, a);
    const bool loop = std::find(compB.begin(), compB.end(), a) != compB.end();
    auto holdsFixed = [&](const std::vector<int>& c) {
      return std::any_of(c.begin(), c.end(), [&](int m) { return s.modules[size_t(m)].fixed; });
    };
    auto partsOf = [&](const std::vector<int>& comp) {
      std::vector<int> parts;
      for (int m : comp)
        for (int p : s.modules[size_t(m)].parts) parts.push_back(p);
      return parts;
    };
    if (!loop && split && !holdsFixed(compA) && !holdsFixed(compB)) {
      // Each side turns about its own centre by its share of the correction `delta` (which would
      // move b's side onto a's): b's by the share a's mass has of the pair's, a's by the rest.
      // Then both shift so the faces mate exactly and the pair's centre (the parts' mass-weighted
      // frames) stays put. Turning about the face instead would swing both sides the same way,
      // 0.095 m x half the angle for a SuperBot: 4 mm for a 5 deg latch.
      const int sym = std::max(1, std::min(defA.symmetry, defB.symmetry));
      const Pose delta = matingFrame(dockPose(s.physics, s.modules[size_t(a)], da), orientation, sym) *
                         dockPose(s.physics, s.modules[size_t(b)], db).inverse();
      const std::vector<int> pa = partsOf(compA), pb = partsOf(compB);
      double massA = 0, massB = 0;
      Vec3 cA = Vec3::Zero(), cB = Vec3::Zero();
      for (int p : pa) {
        massA += s.physics.partMass(p);
        cA += s.physics.partMass(p) * s.physics.partPose(p).pos;
      }
      for (int p : pb) {
        massB += s.physics.partMass(p);
        cB += s.physics.partMass(p) * s.physics.partPose(p).pos;
      }
      // Neither side holds a fixed module, so both have mass; the guards only keep NaN out.
      const double total = std::max(massA + massB, 1e-12);
      cA /= std::max(massA, 1e-12);
      cB /= std::max(massB, 1e-12);
      const double share = massA / total;
      // b moves by Tb = (Rb, tb), a by Ta = (Ra, ta), with Tb = Ta delta (the faces mate):
      // Rb = Ra R and tb = Ra t + ta. ta keeps the pair's centre of mass where it is.
      const Quat rb = Quat::Identity().slerp(share, delta.rot).normalized();
      const Quat ra = (rb * delta.rot.inverse()).normalized();
      const Vec3 ta = -(massA * (ra * cA - cA) + massB * (rb * cB + ra * delta.pos - cB)) / total;
      s.physics.transformParts(pb, Pose{ra * delta.pos + ta, rb});
      s.physics.transformParts(pa, Pose{ta, ra});
    } else if (!loop) {
      const int sym = std::max(1, std::min(defA.symmetry, defB.symmetry));
      if (!holdsFixed(compB)) {
        const Pose delta = matingFrame(dockPose(s.physics, s.modules[size_t(a)], da), orientation, sym) *
                           dockPose(s.physics, s.modules[size_t(b)], db).inverse();
        std::vector<int> parts;
        for (int m : compB)
          for (int p : s.modules[size_t(m)].parts) parts.push_back(p);
        s.physics.transformParts(parts, delta);
      } else if (!holdsFixed(compA)) {
        const Pose delta = matingFrame(dockPose(s.physics, s.modules[size_t(b)], db), orientation, sym) *
                           dockPose(s.physics, s.modules[size_t(a)], da).inverse();
        std::vector<int> parts;
        for (int m : compA)
          for (int p : s.modules[size_t(m)].parts) parts.push_back(p);
        s.physics.transformParts(parts, delta);
      }
    }
  }
  s.physics.lockParts(ma.parts[size_t(defA.link)], mb.parts[size_t(defB.link)]);
  ++m_topology;
  for (auto [st, peer, peerDock] :
       {std::tuple{&ma.docks[size_t(da)], b, db}, std::tuple{&mb.docks[size_t(db)], a, da}}) {
    st->engaged = true;
    st->peerModule = peer;
    st->peerDock = peerDock;
    st->brokeFromModule = st->brokeFromDock = -1;
  }
  Connection c{a, da, b, db, s.time, {}, 0};
  m_connections.push_back(c);
  m_events.push_back({s.time, DockEventKind::Engaged, a, da, b, db});
  if (s.started) {
    ma.dockEvents.emplace_back(da, DockEventKind::Engaged);
    mb.dockEvents.emplace_back(db, DockEventKind::Engaged);
  }
}

void Docking::release(const DockingScene& s, size_t index, DockEventKind kind, double force, double torque) {
  const Connection c = std::move(m_connections[index]);
  m_connections.erase(m_connections.begin() + std::ptrdiff_t(index));
  Module& ma = s.modules[size_t(c.moduleA)];
  Module& mb = s.modules[size_t(c.moduleB)];
  s.physics.unlockParts(ma.parts[size_t(ma.type->docks[size_t(c.dockA)].link)],
                        mb.parts[size_t(mb.type->docks[size_t(c.dockB)].link)]);
  ++m_topology;
  const bool broken = kind == DockEventKind::Broken;
  ma.docks[size_t(c.dockA)].brokeFromModule = broken ? c.moduleB : -1;
  ma.docks[size_t(c.dockA)].brokeFromDock = broken ? c.dockB : -1;
  mb.docks[size_t(c.dockB)].brokeFromModule = broken ? c.moduleA : -1;
  mb.docks[size_t(c.dockB)].brokeFromDock = broken ? c.dockA : -1;
  for (auto [m, d] : {std::pair<Module*, int>{&ma, c.dockA}, std::pair<Module*, int>{&mb, c.dockB}}) {
    DockState& st = m->docks[size_t(d)];
    st.engaged = false;
    st.peerModule = st.peerDock = -1;
    m->dockEvents.emplace_back(d, kind);
  }
  m_released.push_back({c.moduleA, c.dockA});  // their messages in flight are dropped
  m_released.push_back({c.moduleB, c.dockB});
  m_events.push_back({s.time, kind, c.moduleA, c.dockA, c.moduleB, c.dockB, force, torque});
}

bool Docking::disconnect(const DockingScene& s, int m, int dock) {
  for (size_t i = 0; i < m_connections.size(); ++i) {
    const Connection& c = m_connections[i];
    if ((c.moduleA == m && c.dockA == dock) || (c.moduleB == m && c.dockB == dock)) {
      release(s, i, DockEventKind::Disengaged, -1, -1);
      return true;
    }
  }
  return false;
}

void Docking::undock(const DockingScene& s) {
  for (size_t i = 0; i < m_connections.size();) {
    const Connection& c = m_connections[i];
    if (!s.modules[size_t(c.moduleA)].docks[size_t(c.dockA)].enabled ||
        !s.modules[size_t(c.moduleB)].docks[size_t(c.dockB)].enabled)
      release(s, i, DockEventKind::Disengaged, -1, -1);
    else
      ++i;
  }
}

int Docking::bestOrientation(const DockingScene& s, int a, int da, int b, int db) const {
  const DockDef& defA = s.modules[size_t(a)].type->docks[size_t(da)];
  const DockDef& defB = s.modules[size_t(b)].type->docks[size_t(db)];
  const int sym = std::max(1, std::min(defA.symmetry, defB.symmetry));
  const Pose pa = dockPose(s.physics, s.modules[size_t(a)], da),
             pb = dockPose(s.physics, s.modules[size_t(b)], db);
  int best = 0;
  double bestAngle = 1e9;
  for (int k = 0; k < sym; ++k) {
    const Pose want = matingFrame(pa, k, sym);
    const double ang = angleBetween(want.rot * Vec3::UnitZ(), pb.rot * Vec3::UnitZ());
    if (ang < bestAngle) {
      bestAngle = ang;
      best = k;
    }
  }
  return best;
}

template <class Fn>
void Docking::inBlocks(const DockingScene& s, Pace& pace, int n, int size, const Fn& fn) {
  const int blocks = (n + size - 1) / size;
  auto block = [&](int b) { fn(b, b * size, std::min(n, (b + 1) * size)); };
  auto alone = [&] {
    for (int b = 0; b < blocks; ++b) block(b);
  };
  if (!s.tasks || blocks < 2) return alone();
  if (runPaced(
          pace, s.alwaysThreads, [&] { (*s.tasks)(blocks, block); }, alone))
    m_threadedBlocks += blocks;
}

void Docking::poseFreeDocks(const DockingScene& s, size_t k) {
  const DockBox& box = m_dockBoxes[k];
  Module& m = s.modules[box.module];
  if (!box.near) {  // nothing within reach: any broken partner is far away by now
    for (DockState& st : m.docks) st.brokeFromModule = st.brokeFromDock = -1;
    return;
  }
  // One pose per link, not per dock (the first kLinks links; any beyond, per dock).
  constexpr size_t kLinks = 8;
  Pose links[kLinks];
  bool posed[kLinks] = {};
  size_t out = m_boxFirst[k];
  for (size_t d = 0; d < m.docks.size(); ++d) {
    DockState& st = m.docks[d];
    if (!st.enabled || st.engaged || !st.latchable) continue;
    const DockDef& def = m.type->docks[d];
    const size_t link = size_t(def.link);
    if (link < kLinks && !posed[link]) {
      links[link] = linkPose(s.physics, m, def.link);
      posed[link] = true;
    }
    const Pose pose = (link < kLinks ? links[link] : linkPose(s.physics, m, def.link)) * def.frame;
    if (st.brokeFromModule >= 0 &&
        (pose.pos - dockPose(s.physics, s.modules[size_t(st.brokeFromModule)], st.brokeFromDock).pos).norm() >
            def.captureRadius)
      st.brokeFromModule = st.brokeFromDock = -1;
    m_freeDocks[out++] = {int(box.module), int(d), pose, &def};
  }
}

void Docking::findPairs(const DockingScene& s, int i, double cell, std::vector<Hit>& out) const {
  const FreeDock& fa = m_freeDocks[size_t(i)];
  const DockState& sa = s.modules[size_t(fa.module)].docks[size_t(fa.dock)];
  const DockDef& da = *fa.def;
  const Eigen::Vector3i c = cellOf(fa.pose.pos, cell);
  // The 2 x 2 x 2 cells on the dock's side of its own: each axis's two coordinates' keys, made once.
  uint64_t keys[3][2];
  for (int a = 0; a < 3; ++a) {
    const int side = fa.pose.pos[a] / cell - double(c[a]) < 0.5 ? -1 : 1;
    keys[a][0] = axisKey(c[a], a);
    keys[a][1] = axisKey(c[a] + side, a);
  }
  for (int dx = 0; dx < 2; ++dx)
    for (int dy = 0; dy < 2; ++dy)
      for (int dz = 0; dz < 2; ++dz) {
        const uint64_t k = keys[0][dx] ^ keys[1][dy] ^ keys[2][dz];
        if (!cellMayHold(m_cellBits, k)) continue;  // (most of the 8 are empty: no probe of the table)
        // Each pair once: a cell's chain runs from its last dock to its first, so the walk ends at i
        // (it had gone on past every earlier dock, half of each chain on average).
        for (int e = m_cellHead[cellSlot(m_cellKeys, m_cellHead, k)]; e > i; e = m_cellNext[size_t(e)]) {
          const FreeDock& fb = m_freeDocks[size_t(e)];
          if (fb.module == fa.module) continue;
          if (sa.brokeFromModule == fb.module && sa.brokeFromDock == fb.dock) continue;
          const DockDef& db = *fb.def;
          if (!gendersMate(da.gender, db.gender)) continue;
          const Vec3 gapVec = fb.pose.pos - fa.pose.pos;
          const double gap = gapVec.norm();
          if (gap > std::min(da.captureRadius, db.captureRadius)) continue;
          const Vec3 na = fa.pose.rot * Vec3::UnitX(), nb = fb.pose.rot * Vec3::UnitX();
          const double facing = angleBetween(na, -nb);
          if (facing > std::min(da.captureAngle, db.captureAngle)) continue;
          out.push_back({i, e, gapVec, gap, facing, na, nb});
        }
      }
}

void Docking::dock(const DockingScene& s) {
  // Coarse pass: each module with a free dock is a box around its root link, as large as its
  // docks can reach (ModuleTypeDef::dockReach); a sweep along x finds the boxes that overlap.
  // Only those modules' docks are posed and searched below, so isolated modules cost one pose.
  // Each module's root, where it has a free dock, in blocks of modules on the threads where it
  // pays (each writes its own modules' entries); then the boxes in module order, here.
  const int n = int(s.modules.size());
  m_roots.resize(size_t(n));
  inBlocks(s, m_rootPace, n, kModuleBlock, [&](int, int begin, int end) {
    for (int i = begin; i < end; ++i) {
      // With thousands of modules their records, dock states and bodies lie outside the caches:
      // what this pass reads of the module 12 ahead's record, the dock states and parts of the one
      // 8 ahead, and the root link's pose of the one 4 ahead, fetched now (reading the record 4
      // ahead, and the dock states' second line, waited on memory: 30% of the pass at 10,000).
      if (i + 12 < end) {
        const Module& ahead = s.modules[size_t(i + 12)];
        __builtin_prefetch(&ahead.type);
        __builtin_prefetch(&ahead.parts);
        __builtin_prefetch(&ahead.docks);
      }
      if (i + 8 < end) {
        const Module& ahead = s.modules[size_t(i + 8)];
        if (!ahead.docks.empty())
          bullet_layout::fetchRange(ahead.docks.data(), 0, int(ahead.docks.size() * sizeof(DockState)));
        __builtin_prefetch(ahead.parts.data());
      }
      if (i + 4 < end) {
        const Module& ahead = s.modules[size_t(i + 4)];
        if (size_t(ahead.type->rootLink) < ahead.parts.size())
          s.physics.fetchPartPose(ahead.parts[size_t(ahead.type->rootLink)]);
      }
      const Module& m = s.modules[size_t(i)];
      bool anyFree = false;
      for (const DockState& st : m.docks) anyFree |= st.enabled && !st.engaged;
      ModuleRoot& root = m_roots[size_t(i)];
      root.free = anyFree;
      if (anyFree) root.at = linkPose(s.physics, m, m.type->rootLink).pos;
    }
  });
  m_dockBoxes.clear();
  for (int i = 0; i < n; ++i) {
    if (!m_roots[size_t(i)].free) continue;
    const Vec3& c = m_roots[size_t(i)].at;
    const Vec3 r = Vec3::Constant(s.modules[size_t(i)].type->dockReach);
    m_dockBoxes.push_back({c - r, c + r, size_t(i), false});
  }
  // The boxes stay in module order; the sweep sorts their lower x ends (16 bytes each, not the
  // 64-byte boxes, which it then sorted back into module order), within bands along y as tall as
  // the tallest box: a box can only overlap boxes of its own band and the next ones. (A sweep along
  // x alone compared each box with every box of the same column: on a square grid of modules,
  // about sqrt(n) each: 1.6 ms of the step with 10,000 modules.)
  double band = 0, wide = 0;
  for (const DockBox& b : m_dockBoxes) {
    band = std::max(band, b.hi.y() - b.lo.y());
    wide = std::max(wide, b.hi.x() - b.lo.x());
  }
  band *= 1.001;  // (a margin over the rounding of lo.y / band: boxes two bands apart never meet)
  const bool banded = band > 0 && std::isfinite(band) && std::isfinite(wide);
  m_sweep.clear();
  for (size_t k = 0; k < m_dockBoxes.size(); ++k) {
    double row = banded ? std::floor(m_dockBoxes[k].lo.y() / band) : 0.0;
    if (!(row >= -2e9)) row = -2e9;  // (far away, or not a number: the end bands)
    if (!(row <= 2e9)) row = 2e9;
    m_sweep.push_back({m_dockBoxes[k].lo.x(), int32_t(row), uint32_t(k)});
  }
  std::sort(m_sweep.begin(), m_sweep.end(), [](const SweepEnd& a, const SweepEnd& b) {
    return a.row < b.row || (a.row == b.row && (a.x < b.x || (a.x == b.x && a.box < b.box)));
  });
  auto meet = [&](DockBox& ba, DockBox& bb) {
    if (ba.lo.x() <= bb.hi.x() && bb.lo.x() <= ba.hi.x() && ba.lo.y() <= bb.hi.y() &&
        bb.lo.y() <= ba.hi.y() && ba.lo.z() <= bb.hi.z() && bb.lo.z() <= ba.hi.z())
      ba.near = bb.near = true;
  };
  const size_t boxes = m_sweep.size();
  for (size_t first = 0, next = 0; first < boxes; first = next) {
    // This band [first, next), and the one after it if it is the next band along y: [next, last).
    const int32_t row = m_sweep[first].row;
    while (next < boxes && m_sweep[next].row == row) ++next;
    size_t last = next;
    if (next < boxes && int64_t(m_sweep[next].row) == int64_t(row) + 1)
      while (last < boxes && m_sweep[last].row == row + 1) ++last;
    size_t from = next;  // the next band's first box that may still reach the boxes to come
    for (size_t a = first; a < next; ++a) {
      DockBox& ba = m_dockBoxes[m_sweep[a].box];
      for (size_t b = a + 1; b < next && m_sweep[b].x <= ba.hi.x(); ++b)
        meet(ba, m_dockBoxes[m_sweep[b].box]);
      // (A box of the next band ending before this one begins starts at least `wide` before it;
      // twice that, a margin over the rounding.)
      while (from < last && m_sweep[from].x < ba.lo.x() - 2 * wide) ++from;
      for (size_t b = from; b < last && m_sweep[b].x <= ba.hi.x(); ++b) meet(ba, m_dockBoxes[m_sweep[b].box]);
    }
  }
  // Fine pass: the free docks of modules near another, hashed into cells. Each module's free docks
  // get their places first, in module order; then each module poses its own (writing only those
  // places and its own dock states), on the threads where it pays.
  m_boxFirst.resize(m_dockBoxes.size() + 1);
  size_t free = 0;
  for (size_t k = 0; k < m_dockBoxes.size(); ++k) {
    m_boxFirst[k] = free;
    if (m_dockBoxes[k].near)
      for (const DockState& st : s.modules[m_dockBoxes[k].module].docks)
        free += st.enabled && !st.engaged && st.latchable;
  }
  m_boxFirst.back() = free;
  m_freeDocks.resize(free);
  inBlocks(s, m_posePace, int(m_dockBoxes.size()), kBoxBlock, [&](int, int begin, int end) {
    for (int k = begin; k < end; ++k) poseFreeDocks(s, size_t(k));
  });
  if (m_freeDocks.size() < 2) {
    m_candidates.clear();
    updateCaptures(s);
    return;
  }
  // Cells twice the largest capture radius: every dock within reach of a point lies in the 2x2x2
  // block of cells on the point's side of its own cell (8 look-ups, not 27).
  const double cell = 2.0 * m_captureCell;
  // Open-addressing table of cells, each holding a chain of docks (head per slot, next per dock).
  size_t cap = 16;
  while (cap < 2 * m_freeDocks.size()) cap <<= 1;
  m_cellKeys.resize(cap);
  m_cellHead.assign(cap, -1);
  m_cellNext.resize(m_freeDocks.size());
  // Beside the table, a filter of 8 bits a slot (an eighth of the table's bytes: it stays in the
  // first-level cache): a cell whose bit is clear holds no dock, and its look-up is skipped.
  m_cellBits.assign(cap / 8, 0);
  for (size_t i = 0; i < m_freeDocks.size(); ++i) {
    const uint64_t k = cellKey(cellOf(m_freeDocks[i].pose.pos, cell));
    const size_t bit = cellBit(k, cap * 8);
    m_cellBits[bit >> 6] |= uint64_t(1) << (bit & 63);
    const size_t h = cellSlot(m_cellKeys, m_cellHead, k);
    m_cellKeys[h] = k;
    m_cellNext[i] = m_cellHead[h];
    m_cellHead[h] = int(i);
  }
  // The pairs within the capture limits, found dock by dock on the threads where it pays (each
  // block of docks lists its own, in the order it meets them), then taken here in dock order, as
  // one loop over the docks met them: what they do (captures, latches, the magnets' forces)
  // depends on that order.
  const int docks = int(m_freeDocks.size());
  const int blocks = (docks + kDockBlock - 1) / kDockBlock;
  if (m_hits.size() < size_t(blocks)) m_hits.resize(size_t(blocks));
  inBlocks(s, m_pairPace, docks, kDockBlock, [&](int block, int begin, int end) {
    std::vector<Hit>& out = m_hits[size_t(block)];
    out.clear();
    for (int i = begin; i < end; ++i) findPairs(s, i, cell, out);
  });
  m_latches.clear();
  m_candidates.clear();
  // Capture joints need the exact solver; on "pgs" every dock pulls as a magnet.
  const bool jointCapture = s.physics.settings().solver == SolverKind::Exact;
  for (int block = 0; block < blocks; ++block)
    for (const Hit& hit : m_hits[size_t(block)]) {
      const FreeDock& fa = m_freeDocks[size_t(hit.i)];
      const FreeDock& fb = m_freeDocks[size_t(hit.e)];
      const DockDef& da = s.modules[size_t(fa.module)].type->docks[size_t(fa.dock)];
      const DockDef& db = s.modules[size_t(fb.module)].type->docks[size_t(fb.dock)];
      const Vec3& gapVec = hit.gapVec;
      const Vec3 &na = hit.na, &nb = hit.nb;
      const double gap = hit.gap, facing = hit.facing;
      const double latchAngle = std::min(da.latchAngle, db.latchAngle);
      if (jointCapture && da.capture == DockDef::Capture::Joint && db.capture == DockDef::Capture::Joint) {
        // A capture joint draws them in (updateCaptures decides when they latch).
        const int sym = std::max(1, std::min(da.symmetry, db.symmetry));
        const Pose want =
            matingFrame(fa.pose, bestOrientation(s, fa.module, fa.dock, fb.module, fb.dock), sym);
        const double twist = angleBetween(want.rot * Vec3::UnitZ(), fb.pose.rot * Vec3::UnitZ());
        m_candidates.push_back(fa.module < fb.module
                                   ? Candidate{fa.module, fa.dock, fb.module, fb.dock, gap, facing, twist}
                                   : Candidate{fb.module, fb.dock, fa.module, fa.dock, gap, facing, twist});
        continue;
      }
      if (gap <= std::min(da.latchDistance, db.latchDistance) && facing <= latchAngle) {
        const int sym = std::max(1, std::min(da.symmetry, db.symmetry));
        const Pose want =
            matingFrame(fa.pose, bestOrientation(s, fa.module, fa.dock, fb.module, fb.dock), sym);
        if (angleBetween(want.rot * Vec3::UnitZ(), fb.pose.rot * Vec3::UnitZ()) <= latchAngle) {
          m_latches.push_back(fa.module < fb.module ? Latch{fa.module, fa.dock, fb.module, fb.dock}
                                                    : Latch{fb.module, fb.dock, fa.module, fa.dock});
          continue;
        }
      }
      // The magnet: equal and opposite pulls at the two faces, plus a torque turning the
      // faces towards each other.
      const double pull = std::min(da.pull, db.pull);
      if (pull <= 0) continue;
      const Vec3 dir = gap > 1e-9 ? Vec3(gapVec / gap) : Vec3(-na);
      const Module& ma = s.modules[size_t(fa.module)];
      const Module& mb = s.modules[size_t(fb.module)];
      const int pa = ma.parts[size_t(da.link)], pb = mb.parts[size_t(db.link)];
      s.physics.addForce(pa, pull * dir, fa.pose.pos);
      s.physics.addForce(pb, -pull * dir, fb.pose.pos);
      // Torques of the order pull x face size turn the faces square to each other and
      // twist them about the normal into the nearest of their mating orientations: `turn`
      // acts on b, whose normal nb turns towards -na about nb x (-na) = na x nb, and its
      // opposite on a.
      const double arm = pull * std::min(da.size, db.size);
      const int sym = std::max(1, std::min(da.symmetry, db.symmetry));
      const Vec3 wantUp =
          matingFrame(fa.pose, bestOrientation(s, fa.module, fa.dock, fb.module, fb.dock), sym).rot *
          Vec3::UnitZ();
      const Vec3 turn = na.cross(nb) * arm + (fb.pose.rot * Vec3::UnitZ()).cross(wantUp).dot(nb) * nb * arm;
      s.physics.addTorque(pa, -turn);
      s.physics.addTorque(pb, turn);
    }
  updateCaptures(s);
  std::sort(m_latches.begin(), m_latches.end());
  for (const Latch& l : m_latches) {
    const Module& ma = s.modules[size_t(l.a)];
    const Module& mb = s.modules[size_t(l.b)];
    if (ma.docks[size_t(l.da)].engaged || mb.docks[size_t(l.db)].engaged) continue;  // took another this step
    // An earlier latch this step may have moved one side: check the faces again.
    const DockDef& da = ma.type->docks[size_t(l.da)];
    const DockDef& db = mb.type->docks[size_t(l.db)];
    const DockError e = dockError(dockPose(s.physics, s.modules[size_t(l.a)], l.da),
                                  dockPose(s.physics, s.modules[size_t(l.b)], l.db));
    if (e.gap > std::min(da.latchDistance, db.latchDistance) ||
        e.angle > std::min(da.latchAngle, db.latchAngle))
      continue;
    lock(s, l.a, l.da, l.b, l.db, bestOrientation(s, l.a, l.da, l.b, l.db), true, l.split);
  }
}

void Docking::updateCaptures(const DockingScene& s) {
  std::sort(m_candidates.begin(), m_candidates.end());
  m_nextCaptures.clear();
  size_t old = 0;
  for (const Candidate& c : m_candidates) {
    // Captures that are no longer candidates (the faces parted, a dock was disabled or took
    // another) end.
    while (old < m_captures.size() && std::tie(m_captures[old].a, m_captures[old].da, m_captures[old].b,
                                               m_captures[old].db) < std::tie(c.a, c.da, c.b, c.db))
      s.physics.removeCapture(m_captures[old++].id);
    Module& ma = s.modules[size_t(c.a)];
    Module& mb = s.modules[size_t(c.b)];
    const DockDef& da = ma.type->docks[size_t(c.da)];
    const DockDef& db = mb.type->docks[size_t(c.db)];
    Capture cap;
    if (old < m_captures.size() && m_captures[old].a == c.a && m_captures[old].da == c.da &&
        m_captures[old].b == c.b && m_captures[old].db == c.db) {
      cap = m_captures[old++];
    } else {
      const int sym = std::max(1, std::min(da.symmetry, db.symmetry));
      CaptureDesc d;
      d.partA = ma.parts[size_t(da.link)];
      d.partB = mb.parts[size_t(db.link)];
      d.frameA = da.frame;
      d.frameB = db.frame;
      d.mate = matingFrame(Pose{}, bestOrientation(s, c.a, c.da, c.b, c.db), sym).rot;
      d.speed = std::min(da.captureSpeed, db.captureSpeed);
      d.angularSpeed = std::min(da.captureTurnSpeed, db.captureTurnSpeed);
      d.force = std::min(da.captureForce, db.captureForce);
      d.torque = std::min(da.captureTorque, db.captureTorque);
      cap = Capture{c.a, c.da, c.b, c.db, s.physics.addCapture(d), s.time};
      m_events.push_back({s.time, DockEventKind::Captured, c.a, c.da, c.b, c.db});
      if (s.started) {
        ma.dockEvents.emplace_back(c.da, DockEventKind::Captured);
        mb.dockEvents.emplace_back(c.db, DockEventKind::Captured);
      }
    }
    const double angle = std::max(c.facing, c.twist);
    if (c.gap <= std::min(da.latchDistance, db.latchDistance) &&
        angle <= std::min(da.latchAngle, db.latchAngle)) {
      // Inside the latch limits: latch, sharing the last correction between the two sides.
      s.physics.removeCapture(cap.id);
      m_latches.push_back({c.a, c.da, c.b, c.db, true});
      continue;
    }
    if (!cap.stalled && s.time - cap.start >= std::min(da.captureTime, db.captureTime)) {
      cap.stalled = true;
      DockEvent e{s.time, DockEventKind::Stalled, c.a, c.da, c.b, c.db};
      e.gap = c.gap;
      e.angle = angle;
      m_events.push_back(e);
      if (s.started) {
        ma.dockEvents.emplace_back(c.da, DockEventKind::Stalled);
        mb.dockEvents.emplace_back(c.db, DockEventKind::Stalled);
      }
    }
    m_nextCaptures.push_back(cap);
  }
  while (old < m_captures.size()) s.physics.removeCapture(m_captures[old++].id);
  m_captures.swap(m_nextCaptures);
}

void Docking::dropCaptures(const DockingScene& s) {
  for (const Capture& c : m_captures) s.physics.removeCapture(c.id);
  m_captures.clear();
}

Wrench Docking::connectionLoad(const std::vector<Module>& modules, const PhysicsWorld& physics,
                               const Connection& c) const {
  const Module& ma = modules[size_t(c.moduleA)];
  const Module& mb = modules[size_t(c.moduleB)];
  const int pa = ma.parts[size_t(ma.type->docks[size_t(c.dockA)].link)];
  const int pb = mb.parts[size_t(mb.type->docks[size_t(c.dockB)].link)];
  // B's side: the parts locked to B's link without crossing this connection. In a closed loop
  // that reaches A's side too, so only B's own link is counted. Recomputed only when the lock
  // graph has changed.
  if (c.sideOf != m_topology) {
    c.side = physics.lockedGroup(pb, pa, pb);
    if (std::find(c.side.begin(), c.side.end(), pa) != c.side.end()) c.side = {pb};
    c.sideOf = m_topology;
  }
  return physics.internalLoad(c.side, dockPose(physics, modules[size_t(c.moduleB)], c.dockB).pos);
}

void Docking::breakage(const DockingScene& s) {
  // Each connection's load first, on the threads where it pays (a load reads the physics and writes
  // only its own connection's cache), then taken in order. Once one connection has broken, the
  // bodies have changed: the loads of the ones after it are measured again, in turn, as before.
  const int n = int(m_connections.size());
  m_loads.resize(size_t(n));
  inBlocks(s, m_loadPace, n, kLoadBlock, [&](int, int begin, int end) {
    for (int i = begin; i < end; ++i)
      m_loads[size_t(i)] = connectionLoad(s.modules, s.physics, m_connections[size_t(i)]);
  });
  bool broke = false;
  for (size_t i = 0; i < m_connections.size();) {
    const Connection& c = m_connections[i];
    const DockDef& da = s.modules[size_t(c.moduleA)].type->docks[size_t(c.dockA)];
    const DockDef& db = s.modules[size_t(c.moduleB)].type->docks[size_t(c.dockB)];
    const Wrench w = broke ? connectionLoad(s.modules, s.physics, c) : m_loads[i];
    const double f = w.force.norm(), t = w.torque.norm();
    if (f > std::min(da.strength, db.strength) || t > std::min(da.strengthTorque, db.strengthTorque)) {
      release(s, i, DockEventKind::Broken, f, t);
      broke = true;
    } else {
      ++i;
    }
  }
}

}  // namespace rm3d
