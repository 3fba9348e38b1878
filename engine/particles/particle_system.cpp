// The particle engine's step: predict, sort by cell, neighbour lists, a fixed number of
// iterations (fluid: Jacobi density passes; debris: grain contact passes), each followed by the
// collisions with the bodies, velocities and XSPH viscosity, and the push on each body. See
// particle_system.h for the scheme.
#include "particles/particle_system.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstring>
#include <limits>

#include "particles/particle_contact.h"
#include "particles/particle_walls.h"

namespace rm3d {

namespace {

constexpr int kBlock = 512;    // particles per unit of parallel work
constexpr int kRowChunk = 64;  // candidates tested at a time in the neighbour scan
constexpr float kPiF = 3.14159265358979f;
// Debris (Macklin et al. 2014, sections 4-6, and granularPass below).
constexpr float kGrainReach = 1.2f;    // neighbour lists reach this many spacings (grains touch at one)
constexpr float kGrainTouch = 1.05f;   // a grain within this many radii of a surface has friction on it
constexpr float kGrainShock = 1.25f;   // the upper grain's share of a contact: 0.5 + this x height / spacing
constexpr float kGrainWeight = 1e-3f;  // spacings added to each depth weight (no 0 / 0)
constexpr float kGrainJitter = 1.0f;   // initial offsets from the lattice, in spacings (each way half)
constexpr int kGrainRelax = 30;        // Gauss-Seidel passes relaxing the overlaps those make
constexpr int kGrainSlabs = 3;         // slabs of height per layer of cells in the solve order
constexpr int kGrainColumn = 16;       // columns of cells solved by one thread are this many cells wide
constexpr float kGrainSleep = 0.5f;    // spacings a second: grains slower than this stay put
// Friction between grains is limited by at least this share of |g| dt^2 (what gravity presses a
// resting grain in by in a step): with 1, heaps of friction 0.6 stood at 41 degrees; with 0,
// resolved contacts had almost none (21 degrees); a half gives 33, as dry sand.
constexpr float kGrainLoad = 0.5f;
constexpr uint32_t kAhead = 6, kNear = 2;  // prefetch distances in the solve order

using Clock = std::chrono::steady_clock;
double msSince(Clock::time_point a) {
  return std::chrono::duration<double, std::milli>(Clock::now() - a).count();
}

/// Deterministic jitter in [-0.5, 0.5) from an index (a lattice at rest is a degenerate state).
float jitter(uint32_t i, uint32_t salt) {
  uint32_t h = i * 0x9E3779B1u ^ salt * 0x85EBCA77u;
  h ^= h >> 15;
  h *= 0x2C1B3C6Du;
  h ^= h >> 12;
  return float(h & 0xFFFFu) / 65536.0f - 0.5f;
}

int cellCoord(float v, float origin, float inv, int dim) {
  const float c = (v - origin) * inv;
  if (!(c >= 0)) return 0;  // also NaN
  if (c >= float(dim - 1)) return dim - 1;
  return int(c);
}

}  // namespace

double ParticleDef::particleCount() const {
  const Vec3 e = max - min;
  double n = 1;
  for (int a = 0; a < 3; ++a) n *= std::floor(e[a] / spacing + 1e-6);
  return n;
}

ParticleSystem::ParticleSystem(const ParticleDef& def) : m_def(def) {
  if (m_def.kineticFriction < 0) m_def.kineticFriction = 0.8 * m_def.friction;
  m_substeps = m_def.substeps > 0                       ? m_def.substeps
               : m_def.kind == ParticleDef::Kind::Fluid ? m_def.iterations
                                                        : 1;
  m_spacing = float(def.spacing);
  m_radius = 0.5f * m_spacing;
  m_mass = def.density * def.spacing * def.spacing * def.spacing;
  // Debris: contacts between grains (granularPass), found within a little more than the
  // touching distance (pairs that come into contact during the iterations); the fluid's
  // constants below are then unused.
  const bool granular = def.kind == ParticleDef::Kind::Debris;
  m_h = granular ? kGrainReach * m_spacing : float(def.kernel) * m_spacing;
  m_stride = granular ? kMaxGrainNeighbours : kMaxNeighbours;
  {
    // Density in units of the rest density: the kernel sum of a particle inside a cubic lattice
    // at the spacing. Gradients of C_i = S_i / S_0 - 1 with spiky's gradient.
    const float h2 = m_h * m_h;
    const float poly6 = 315.0f / (64.0f * kPiF * std::pow(m_h, 9.0f));
    const float spiky = 45.0f / (kPiF * std::pow(m_h, 6.0f));
    const int reach = int(std::ceil(m_h / m_spacing));
    double sum = 0, grad2 = 0;
    Vec3 g = Vec3::Zero();
    for (int i = -reach; i <= reach; ++i)
      for (int j = -reach; j <= reach; ++j)
        for (int k = -reach; k <= reach; ++k) {
          const Vec3 d = Vec3(i, j, k) * double(m_spacing);
          const double r2 = d.squaredNorm();
          if (r2 >= h2) continue;
          sum += std::pow(h2 - r2, 3.0);
          if (r2 > 0) {
            const double r = std::sqrt(r2);
            const Vec3 gr = -spiky * (m_h - r) * (m_h - r) / r * d;
            grad2 += gr.squaredNorm();
            g += gr;
          }
        }
    m_restSum = float(sum * poly6);
    m_poly6 = poly6 / m_restSum;
    m_spiky = spiky / m_restSum;
    const double g0 = (grad2 + g.squaredNorm()) / (double(m_restSum) * m_restSum);
    m_eps = float(0.05 * g0);  // constraint softening, relative to the rest stiffness
    m_scorrK = float(def.tension / g0);
    const float dq2 = 0.04f * h2;  // Delta q = 0.2 h
    m_scorrW = 1.0f / ((h2 - dq2) * (h2 - dq2) * (h2 - dq2));
    // A solid half-space at distance s: the share of the kernel's mass beyond it, the integral
    // of poly6 over slices, pi/4 (h^2 - z^2)^4 at height z, from s to h, over the whole ball.
    auto slice = [&](double z) { return std::pow(double(h2) - z * z, 4.0); };
    const int steps = 2000;
    std::vector<double> cum(steps + 1, 0.0);  // integral from z to h, z = -h + k (2h / steps)
    const double dz = 2.0 * m_h / steps;
    for (int k = steps - 1; k >= 0; --k) {
      const double z0 = -m_h + k * dz;
      cum[size_t(k)] = cum[size_t(k + 1)] + dz / 6 * (slice(z0) + 4 * slice(z0 + dz / 2) + slice(z0 + dz));
    }
    const double total = cum[0];
    for (int k = 0; k <= kWallTable; ++k) {
      const double sd = double(m_h) * k / kWallTable;
      const int at = std::min(steps, int(std::lround((sd + m_h) / dz)));
      m_wallShare[k] = float(cum[size_t(at)] / total);
      m_wallSlope[k] = float(-slice(sd) / total);
    }
  }
  fill();
}

void ParticleSystem::fill() {
  const Vec3 e = m_def.max - m_def.min;
  int n[3];
  for (int a = 0; a < 3; ++a) n[a] = std::max(0, int(std::floor(e[a] / m_def.spacing + 1e-6)));
  m_n = n[0] * n[1] * n[2];
  // Centre the lattice in the box.
  Vec3 start;
  for (int a = 0; a < 3; ++a) start[a] = m_def.min[a] + 0.5 * (e[a] - (n[a] - 1) * m_def.spacing);
  const size_t N = size_t(m_n);
  for (auto* v :
       {&m_px, &m_py, &m_pz, &m_vx, &m_vy, &m_vz, &m_qx, &m_qy, &m_qz, &m_dx, &m_dy, &m_dz, &m_lambda})
    v->assign(N, 0.0f);
  m_id.resize(N);
  m_cell.assign(N, 0);
  m_perm.resize(N);
  m_tmpId.resize(N);
  m_tmp.resize(9 * N);
  m_nbr.assign(N * size_t(m_stride), 0);
  m_nbrCount.assign(N, 0);
  m_touchBody.assign(2 * N, -1);
  m_touch.assign(12 * N, 0.0f);
  for (auto* v : {&m_wallS, &m_wallGx, &m_wallGy, &m_wallGz}) v->assign(N, 0.0f);
  m_slotG.assign(6 * N, 0.0f);
  const float jit = 0.02f * m_spacing;
  uint32_t i = 0;
  for (int z = 0; z < n[2]; ++z)
    for (int y = 0; y < n[1]; ++y)
      for (int x = 0; x < n[0]; ++x, ++i) {
        m_px[i] = float(start.x() + x * m_def.spacing) + jit * jitter(i, 1);
        m_py[i] = float(start.y() + y * m_def.spacing) + jit * jitter(i, 2);
        m_pz[i] = float(start.z() + z * m_def.spacing) + jit * jitter(i, 3);
        m_id[i] = i;
      }
  if (m_def.kind == ParticleDef::Kind::Debris) disorder(n);
}

void ParticleSystem::disorder(const int n[3]) {
  // Grains with friction on a lattice make a solid (each rests squarely on the one below: a
  // column stands). Each is moved off its site by up to half a spacing each way, then the
  // overlaps this makes are relaxed by Gauss-Seidel passes over the lattice neighbours (each
  // pair once, in lattice order: deterministic), the centres kept inside the box (a quarter
  // spacing in from its sides and top, a radius above its floor).
  const float amp = kGrainJitter * m_spacing, d = m_spacing, d2 = d * d;
  float* pos[3] = {m_px.data(), m_py.data(), m_pz.data()};
  float lo[3], hi[3];
  for (int a = 0; a < 3; ++a) {
    lo[a] = float(m_def.min[a]) + (a == 2 ? 1.0f : 0.5f) * m_radius;
    hi[a] = std::max(lo[a], float(m_def.max[a]) - 0.5f * m_radius);
    for (int i = 0; i < m_n; ++i)
      pos[a][i] = std::clamp(pos[a][i] + amp * jitter(uint32_t(i), uint32_t(4 + a)), lo[a], hi[a]);
  }
  auto site = [&](int x, int y, int z) {
    return (size_t(z) * size_t(n[1]) + size_t(y)) * size_t(n[0]) + size_t(x);
  };
  for (int pass = 0; pass < kGrainRelax; ++pass)
    for (int z = 0; z < n[2]; ++z)
      for (int y = 0; y < n[1]; ++y)
        for (int x = 0; x < n[0]; ++x) {
          const size_t i = site(x, y, z);
          // The 13 neighbours ahead in lattice order.
          for (int c = 0; c <= 1; ++c)
            for (int b = -1; b <= 1; ++b)
              for (int a = -1; a <= 1; ++a) {
                if (c == 0 && (b < 0 || (b == 0 && a <= 0))) continue;
                const int X = x + a, Y = y + b, Z = z + c;
                if (X < 0 || Y < 0 || X >= n[0] || Y >= n[1] || Z >= n[2]) continue;
                const size_t j = site(X, Y, Z);
                const float e[3] = {pos[0][i] - pos[0][j], pos[1][i] - pos[1][j], pos[2][i] - pos[2][j]};
                const float r2 = e[0] * e[0] + e[1] * e[1] + e[2] * e[2];
                if (!(r2 < d2) || r2 < 1e-12f * d2) continue;
                const float f = 0.5f * (d / std::sqrt(r2) - 1.0f);
                for (int k = 0; k < 3; ++k) {
                  pos[k][i] = std::clamp(pos[k][i] + f * e[k], lo[k], hi[k]);
                  pos[k][j] = std::clamp(pos[k][j] - f * e[k], lo[k], hi[k]);
                }
              }
        }
}

void ParticleSystem::sleep(float dt, const ParallelFor& parallel) {
  // Particle sleeping (Macklin et al. 2014): a grain that would move slower than kGrainSleep
  // spacings a second stays where it is, at rest, so what the few iterations leave unresolved
  // does not make a settled heap creep.
  const float *px = m_px.data(), *py = m_py.data(), *pz = m_pz.data();
  float *qx = m_qx.data(), *qy = m_qy.data(), *qz = m_qz.data();
  const float still = kGrainSleep * m_spacing * dt, still2 = still * still;
  forBlocks(parallel, [&](int b, int e) {
    for (int i = b; i < e; ++i) {
      const float dx = qx[i] - px[i], dy = qy[i] - py[i], dz = qz[i] - pz[i];
      if (dx * dx + dy * dy + dz * dz < still2) {
        qx[i] = px[i];
        qy[i] = py[i];
        qz[i] = pz[i];
      }
    }
  });
}

template <class F>
void ParticleSystem::forBlocks(const ParallelFor& parallel, F&& fn) const {
  const int blocks = (m_n + kBlock - 1) / kBlock;
  // Two pointers: fits std::function's own storage, so no allocation per pass.
  auto one = [this, &fn](int b) { fn(b * kBlock, std::min(m_n, (b + 1) * kBlock)); };
  if (parallel && blocks > 1)
    parallel(blocks, one);
  else
    for (int b = 0; b < blocks; ++b) one(b);
}

void ParticleSystem::step(double dt, const Vec3& gravity, const ColliderSet& colliders,
                          const ParallelFor& parallel) {
  m_pushes.clear();
  if (m_n == 0 || !(dt > 0)) return;
  const int iterations = std::max(0, m_def.iterations);
  const int substeps = std::max(1, std::min(m_substeps, iterations));
  const float h = float(dt), hs = float(dt / substeps);
  m_minLoad = float(gravity.norm() * double(hs) * double(hs));
  // Substeps compress a deep pool far less (a 10-layer pool at 1.4 cm spacing by 7 % instead of
  // 21 %), and there 1.5 keeps the surface calm where 2 would throw single particles up.
  m_omega = substeps > 1 ? 1.5f : 2.0f;
  m_dt = hs;
  auto t = Clock::now();
  // The grid and the neighbour lists are made once a step, at the positions predicted for its
  // end; the substeps then start again from the step's start.
  predict(h, gravity, parallel, substeps == 1);
  sortByCell(parallel);
  m_times.sort = msSince(t);
  t = Clock::now();
  const bool granular = m_def.kind == ParticleDef::Kind::Debris;
  buildNeighbours(parallel);
  markColliderCells(colliders, h);
  if (granular) orderGrains();
  m_times.neighbours = msSince(t);
  t = Clock::now();
  m_ground = colliders.ground;
  for (int sub = 0; sub < substeps; ++sub) {
    // The iterations spread over the substeps, the first ones taking what does not divide.
    const int its = iterations / substeps + (sub < iterations % substeps ? 1 : 0);
    if (substeps > 1) {
      if (sub > 0) advance(hs, parallel);
      predict(hs, gravity, parallel, true);
    }
    if (granular) granularPass(true, parallel);                 // stabilisation (Macklin et al. 2014, 4.4)
    applyAndCollide(hs, false, its == 0, colliders, parallel);  // contacts and wall terms at the start
    for (int it = 0; it < its; ++it) {
      if (granular)
        granularPass(false, parallel);
      else
        fluidIteration(colliders, parallel);
      applyAndCollide(hs, !granular, it == its - 1, colliders, parallel);
    }
  }
  m_times.solve = msSince(t);
  t = Clock::now();
  if (granular) sleep(hs, parallel);
  finish(hs, parallel);
  reducePushes(h, substeps, colliders);
  m_times.finish = msSince(t);
}

void ParticleSystem::predict(float dt, const Vec3& gravity, const ParallelFor& parallel, bool store) {
  const float gx = float(gravity.x()) * dt, gy = float(gravity.y()) * dt, gz = float(gravity.z()) * dt;
  const float keep = std::max(0.0f, 1.0f - float(m_def.damping) * dt);
  const float vmax = float(m_def.maxSpeed), vmax2 = vmax * vmax;
  const int blocks = (m_n + kBlock - 1) / kBlock;
  m_blockLo.assign(size_t(blocks) * 3, std::numeric_limits<float>::max());
  m_blockHi.assign(size_t(blocks) * 3, -std::numeric_limits<float>::max());
  float *px = m_px.data(), *py = m_py.data(), *pz = m_pz.data();
  float *vx = m_vx.data(), *vy = m_vy.data(), *vz = m_vz.data();
  float *qx = m_qx.data(), *qy = m_qy.data(), *qz = m_qz.data();
  forBlocks(parallel, [&](int b, int e) {
    float lo[3] = {std::numeric_limits<float>::max(), std::numeric_limits<float>::max(),
                   std::numeric_limits<float>::max()};
    float hi[3] = {-lo[0], -lo[0], -lo[0]};
    for (int i = b; i < e; ++i) {
      float ux = (vx[i] + gx) * keep, uy = (vy[i] + gy) * keep, uz = (vz[i] + gz) * keep;
      const float s2 = ux * ux + uy * uy + uz * uz;
      if (s2 > vmax2) {
        const float f = vmax / std::sqrt(s2);
        ux *= f;
        uy *= f;
        uz *= f;
      }
      if (store) {
        vx[i] = ux;
        vy[i] = uy;
        vz[i] = uz;
      }
      qx[i] = px[i] + ux * dt;
      qy[i] = py[i] + uy * dt;
      qz[i] = pz[i] + uz * dt;
      const float p[3] = {qx[i], qy[i], qz[i]};
      for (int a = 0; a < 3; ++a) {  // comparisons leave NaN out
        if (p[a] < lo[a]) lo[a] = p[a];
        if (p[a] > hi[a]) hi[a] = p[a];
      }
    }
    const int k = b / kBlock;
    for (int a = 0; a < 3; ++a) {
      m_blockLo[size_t(3 * k + a)] = lo[a];
      m_blockHi[size_t(3 * k + a)] = hi[a];
    }
  });
}

void ParticleSystem::sortByCell(const ParallelFor& parallel) {
  // The grid: the particles' bounding box in cells as wide as the neighbour radius, capped at
  // about two cells per particle (wider cells past that, then a box around the middle; a
  // particle outside the grid joins the nearest border cell, which keeps the 27-cell scan exact,
  // since clamping never moves two cells apart).
  float lo[3], hi[3];
  for (int a = 0; a < 3; ++a) {
    lo[a] = std::numeric_limits<float>::max();
    hi[a] = -lo[a];
  }
  const size_t blocks = m_blockLo.size() / 3;
  for (size_t k = 0; k < blocks; ++k)
    for (int a = 0; a < 3; ++a) {
      lo[a] = std::min(lo[a], m_blockLo[3 * k + size_t(a)]);
      hi[a] = std::max(hi[a], m_blockHi[3 * k + size_t(a)]);
    }
  for (int a = 0; a < 3; ++a)
    if (!(lo[a] <= hi[a])) lo[a] = hi[a] = 0;  // no finite particle
  const double cap = 2.0 * m_n + 4096;
  float cs = m_h;
  auto cells = [&](float size) {
    double c = 1;
    for (int a = 0; a < 3; ++a) c *= std::floor(double(hi[a] - lo[a]) / size) + 1;
    return c;
  };
  while (cells(cs) > cap && cs < 2 * m_h) cs *= 1.25f;
  if (cells(cs) > cap) {
    const double f = std::cbrt(cap / cells(cs)) * 0.95;
    for (int a = 0; a < 3; ++a) {
      const float mid = 0.5f * (lo[a] + hi[a]), half = float(0.5 * (hi[a] - lo[a]) * f);
      lo[a] = mid - half;
      hi[a] = mid + half;
    }
  }
  m_cellSize = cs;
  m_invCell = 1.0f / cs;
  for (int a = 0; a < 3; ++a) {
    m_origin[a] = lo[a];
    m_dims[a] = std::max(1, int(std::floor((hi[a] - lo[a]) * m_invCell)) + 1);
  }
  const size_t ncells = size_t(m_dims[0]) * size_t(m_dims[1]) * size_t(m_dims[2]);

  const float *qx = m_qx.data(), *qy = m_qy.data(), *qz = m_qz.data();
  uint32_t* cell = m_cell.data();
  forBlocks(parallel, [&](int b, int e) {
    for (int i = b; i < e; ++i) {
      const int cx = cellCoord(qx[i], m_origin[0], m_invCell, m_dims[0]);
      const int cy = cellCoord(qy[i], m_origin[1], m_invCell, m_dims[1]);
      const int cz = cellCoord(qz[i], m_origin[2], m_invCell, m_dims[2]);
      cell[i] = uint32_t((cz * m_dims[1] + cy) * m_dims[0] + cx);
    }
  });
  // Counting sort (stable): counts, starts, then each particle's new place.
  m_cellStart.assign(ncells + 1, 0);
  uint32_t* start = m_cellStart.data();
  for (int i = 0; i < m_n; ++i) ++start[cell[i] + 1];
  for (size_t c = 0; c < ncells; ++c) start[c + 1] += start[c];
  m_cursor.assign(m_cellStart.begin(), m_cellStart.end() - 1);
  uint32_t* perm = m_perm.data();
  for (int i = 0; i < m_n; ++i) perm[m_cursor[cell[i]]++] = uint32_t(i);
  // Gather every array into the new order (each destination written once).
  float* arrays[9] = {m_px.data(), m_py.data(), m_pz.data(), m_vx.data(), m_vy.data(),
                      m_vz.data(), m_qx.data(), m_qy.data(), m_qz.data()};
  float* tmp = m_tmp.data();
  const size_t N = size_t(m_n);
  uint32_t* tmpId = m_tmpId.data();
  const uint32_t* id = m_id.data();
  forBlocks(parallel, [&](int b, int e) {
    for (int k = 0; k < 9; ++k) {
      const float* src = arrays[k];
      float* dst = tmp + size_t(k) * N;
      for (int i = b; i < e; ++i) dst[i] = src[perm[i]];
    }
    for (int i = b; i < e; ++i) tmpId[i] = id[perm[i]];
  });
  forBlocks(parallel, [&](int b, int e) {
    for (int k = 0; k < 9; ++k)
      std::memcpy(arrays[k] + b, tmp + size_t(k) * N + size_t(b), sizeof(float) * size_t(e - b));
  });
  std::swap(m_id, m_tmpId);
  // Cells in the new order: ascending runs given by the starts.
  for (size_t c = 0; c < ncells; ++c)
    for (uint32_t i = start[c]; i < start[c + 1]; ++i) cell[i] = uint32_t(c);
}

void ParticleSystem::buildNeighbours(const ParallelFor& parallel) {
  const float *qx = m_qx.data(), *qy = m_qy.data(), *qz = m_qz.data();
  const uint32_t* start = m_cellStart.data();
  uint32_t* nbr = m_nbr.data();
  uint8_t* count = m_nbrCount.data();
  int32_t* touchBody = m_touchBody.data();
  const float r2max = m_h * m_h;
  const int nx = m_dims[0], ny = m_dims[1], nz = m_dims[2], stride = m_stride;
  forBlocks(parallel, [&](int b, int e) {
    for (int i = b; i < e; ++i) {
      touchBody[2 * i] = touchBody[2 * i + 1] = -1;
      const float xi = qx[i], yi = qy[i], zi = qz[i];
      const int cx = cellCoord(xi, m_origin[0], m_invCell, nx);
      const int cy = cellCoord(yi, m_origin[1], m_invCell, ny);
      const int cz = cellCoord(zi, m_origin[2], m_invCell, nz);
      const int x0 = std::max(cx - 1, 0), x1 = std::min(cx + 1, nx - 1);
      // Branch-free: every candidate is written, the count moves on only for a neighbour (a
      // buffer with room for a full row keeps the writes in bounds).
      uint32_t* out = nbr + size_t(i) * size_t(stride);
      int n = 0;
      for (int z = std::max(cz - 1, 0); z <= std::min(cz + 1, nz - 1); ++z)
        for (int y = std::max(cy - 1, 0); y <= std::min(cy + 1, ny - 1); ++y) {
          const size_t row = (size_t(z) * size_t(ny) + size_t(y)) * size_t(nx);
          uint32_t j = start[row + size_t(x0)];
          const uint32_t je = start[row + size_t(x1) + 1];
          while (j < je) {
            uint32_t buf[kRowChunk];
            const uint32_t end = std::min(je, j + uint32_t(kRowChunk));
            int m = 0;
            for (; j < end; ++j) {
              const float dx = xi - qx[j], dy = yi - qy[j], dz = zi - qz[j];
              const float d2 = dx * dx + dy * dy + dz * dz;
              buf[m] = j;
              m += int(d2 < r2max) & int(j != uint32_t(i));
            }
            const int take = std::min(m, stride - n);
            std::memcpy(out + n, buf, sizeof(uint32_t) * size_t(take));
            n += take;
          }
        }
      count[i] = uint8_t(n);
    }
  });
}

void ParticleSystem::markColliderCells(const ColliderSet& colliders, float dt) {
  const size_t ncells = size_t(m_dims[0]) * size_t(m_dims[1]) * size_t(m_dims[2]);
  // Every shape within reach of a cell, however many (a cap would drop a wall where many shapes
  // meet): counted, then listed. The reach also covers half a step at full speed, so a step's
  // path lies within reach of its start's or its end's cell (the walls' guard).
  const float margin = std::max(m_cellSize, 0.6f * float(m_def.maxSpeed) * dt) + m_radius;
  const size_t nshapes = colliders.shapes.size();
  m_shapeCells.resize(6 * nshapes);
  for (size_t s = 0; s < nshapes; ++s) {
    const ColliderShape& c = colliders.shapes[s];
    int* box = m_shapeCells.data() + 6 * s;
    bool outside = false;
    for (int a = 0; a < 3; ++a) {
      const float gridHi = m_origin[a] + float(m_dims[a]) * m_cellSize;
      // A shape wholly past the grid's border still touches the border cells' strays only if
      // it reaches them; cells past the border are clamped like particles are.
      if (c.hi[a] + margin < m_origin[a] - 4 * m_cellSize || c.lo[a] - margin > gridHi + 4 * m_cellSize)
        outside = true;
      box[a] = cellCoord(c.lo[a] - margin, m_origin[a], m_invCell, m_dims[a]);
      box[3 + a] = cellCoord(c.hi[a] + margin, m_origin[a], m_invCell, m_dims[a]);
    }
    if (outside) box[0] = box[3] + 1;  // empty
  }
  m_cellShapeStart.assign(ncells + 1, 0);
  uint32_t* start = m_cellShapeStart.data();
  auto forCells = [&](const int* box, auto&& fn) {
    for (int z = box[2]; z <= box[5]; ++z)
      for (int y = box[1]; y <= box[4]; ++y) {
        const size_t row = (size_t(z) * size_t(m_dims[1]) + size_t(y)) * size_t(m_dims[0]);
        for (int x = box[0]; x <= box[3]; ++x) fn(row + size_t(x));
      }
  };
  for (size_t s = 0; s < nshapes; ++s)
    forCells(m_shapeCells.data() + 6 * s, [&](size_t c) { ++start[c + 1]; });
  for (size_t c = 0; c < ncells; ++c) start[c + 1] += start[c];
  m_cellShapes.resize(start[ncells]);
  m_cursor.assign(m_cellShapeStart.begin(), m_cellShapeStart.end() - 1);
  for (size_t s = 0; s < nshapes; ++s)
    forCells(m_shapeCells.data() + 6 * s, [&](size_t c) { m_cellShapes[m_cursor[c]++] = int32_t(s); });
}

void ParticleSystem::fluidIteration(const ColliderSet& colliders, const ParallelFor& parallel) {
  const float *qx = m_qx.data(), *qy = m_qy.data(), *qz = m_qz.data();
  const uint32_t* nbr = m_nbr.data();
  const uint8_t* count = m_nbrCount.data();
  float* lambda = m_lambda.data();
  const float *wallS = m_wallS.data(), *wallGx = m_wallGx.data(), *wallGy = m_wallGy.data(),
              *wallGz = m_wallGz.data();
  const float h = m_h, h2 = h * h, poly6 = m_poly6, spiky = m_spiky, eps = m_eps;
  const float self = h2 * h2 * h2;
  // Over-relaxed lambdas (m_omega, set by step()): twice the plain step halves how much a deep
  // pool is compressed at 3 iterations in one step, and stays stable with the step limit below.
  const float kOmega = m_omega;
  forBlocks(parallel, [&](int b, int e) {
    for (int i = b; i < e; ++i) {
      const float xi = qx[i], yi = qy[i], zi = qz[i];
      const uint32_t* nb = nbr + size_t(i) * kMaxNeighbours;
      float sum = self, gx = 0, gy = 0, gz = 0, g2 = 0;
      for (int k = 0, n = count[i]; k < n; ++k) {
        const uint32_t j = nb[k];
        const float dx = xi - qx[j], dy = yi - qy[j], dz = zi - qz[j];
        // Branch-free: outside the kernel (moved away since the lists were built) t and w
        // are 0; at zero distance the gradient is 0.
        const float r2 = dx * dx + dy * dy + dz * dz;
        const float t = std::max(h2 - r2, 0.0f);
        sum += t * t * t;
        const float r = std::sqrt(r2);
        const float w = std::max(h - r, 0.0f), g = spiky * w * w / std::max(r, 1e-9f);
        gx += g * dx;
        gy += g * dy;
        gz += g * dz;
        g2 += g * g * r2;
      }
      // The bodies next to i stand in for the particles their volume would hold. (g sums the
      // neighbours' gradient with the opposite sign: the wall's, the density's own gradient,
      // is taken off, so the two partly cancel as they do in the constraint's true gradient.)
      const float c = sum * poly6 + wallS[i] - 1.0f;
      gx -= wallGx[i];
      gy -= wallGy[i];
      gz -= wallGz[i];
      lambda[i] = c > 0 ? -kOmega * c / (gx * gx + gy * gy + gz * gz + g2 + eps) : 0.0f;
    }
  });
  float *dxo = m_dx.data(), *dyo = m_dy.data(), *dzo = m_dz.data();
  // At most a fifth of the spacing per iteration: with few Jacobi iterations a deep pool's
  // bottom is compressed, and larger steps there throw the top particles up.
  const float scorrK = m_scorrK, scorrW = m_scorrW, maxStep = 0.2f * m_spacing;
  const int32_t* touchBody = m_touchBody.data();
  const float* slotG = m_slotG.data();
  float* touch = m_touch.data();
  forBlocks(parallel, [&](int b, int e) {
    for (int i = b; i < e; ++i) {
      const float xi = qx[i], yi = qy[i], zi = qz[i], li = lambda[i];
      const uint32_t* nb = nbr + size_t(i) * kMaxNeighbours;
      float ax = 0, ay = 0, az = 0;
      for (int k = 0, n = count[i]; k < n; ++k) {
        const uint32_t j = nb[k];
        const float dx = xi - qx[j], dy = yi - qy[j], dz = zi - qz[j];
        const float r2 = dx * dx + dy * dy + dz * dz;
        const float r = std::sqrt(r2);
        const float t = std::max(h2 - r2, 0.0f), ratio = t * t * t * scorrW, ratio2 = ratio * ratio;
        const float corr = -scorrK * ratio2 * ratio2;  // s_corr = -k (W / W(dq))^4
        const float w = std::max(h - r, 0.0f),
                    s = (li + lambda[j] + corr) * spiky * w * w / std::max(r, 1e-9f);
        ax += s * dx;
        ay += s * dy;
        az += s * dz;
      }
      // lambda < 0 pushes apart: C's gradient on i points away from j, and the step is
      // lambda times it, so the sign is the gradient's (-spiky (h-r)^2 r^).
      ax = -ax + li * wallGx[i];
      ay = -ay + li * wallGy[i];
      az = -az + li * wallGz[i];
      // The bodies' share of that push, for their reaction.
      for (int slot = 0; slot < 2; ++slot) {
        if (touchBody[2 * i + slot] < 0 || li == 0) continue;
        const float* g = slotG + 6 * size_t(i) + 3 * size_t(slot);
        float* acc = touch + 12 * size_t(i) + 6 * size_t(slot);
        const float fx = li * g[0], fy = li * g[1], fz = li * g[2];
        acc[0] += fx;
        acc[1] += fy;
        acc[2] += fz;
        const ColliderBody& body = colliders.bodies[size_t(touchBody[2 * i + slot])];
        const float arm[3] = {xi - float(body.com[0]), yi - float(body.com[1]), zi - float(body.com[2])};
        acc[3] += arm[1] * fz - arm[2] * fy;
        acc[4] += arm[2] * fx - arm[0] * fz;
        acc[5] += arm[0] * fy - arm[1] * fx;
      }
      const float m2 = ax * ax + ay * ay + az * az;
      if (m2 > maxStep * maxStep) {
        const float f = maxStep / std::sqrt(m2);
        ax *= f;
        ay *= f;
        az *= f;
      }
      dxo[i] = ax;
      dyo[i] = ay;
      dzo[i] = az;
    }
  });
}

void ParticleSystem::orderGrains() {
  // Columns of kGrainColumn x kGrainColumn cells, listed colour by colour (two columns of a
  // colour are a column apart, so no grains of theirs touch); within each, its grains layer by
  // layer of cells from the bottom and, within a layer, by slabs of height (a grain resting on
  // another comes after it: the stack is held from the bottom up within one pass).
  const int nxc = m_dims[0], nyc = m_dims[1], nzc = m_dims[2];
  const int bx = (nxc + kGrainColumn - 1) / kGrainColumn, by = (nyc + kGrainColumn - 1) / kGrainColumn;
  const float slabInv = float(kGrainSlabs) / m_cellSize;
  const uint32_t* start = m_cellStart.data();
  const float* qz = m_qz.data();
  m_order.resize(size_t(m_n));
  m_orderColumn.clear();
  uint32_t w = 0;
  for (int colour = 0; colour < 4; ++colour) {
    m_orderColour[colour] = int(m_orderColumn.size());
    for (int Y = colour >> 1; Y < by; Y += 2)
      for (int X = colour & 1; X < bx; X += 2) {
        m_orderColumn.push_back(w);
        const int xa = X * kGrainColumn, xb = std::min(nxc, xa + kGrainColumn);
        const int ya = Y * kGrainColumn, yb = std::min(nyc, ya + kGrainColumn);
        for (int cz = 0; cz < nzc; ++cz) {
          const float zBase = m_origin[2] + float(cz) * m_cellSize;
          for (int slab = 0; slab < kGrainSlabs; ++slab)
            for (int cy = ya; cy < yb; ++cy) {
              const size_t row = (size_t(cz) * size_t(nyc) + size_t(cy)) * size_t(nxc);
              for (uint32_t i = start[row + size_t(xa)], e = start[row + size_t(xb)]; i < e; ++i)
                if (std::clamp(int((qz[i] - zBase) * slabInv), 0, kGrainSlabs - 1) == slab) m_order[w++] = i;
            }
        }
      }
  }
  m_orderColour[4] = int(m_orderColumn.size());
  m_orderColumn.push_back(w);
}

void ParticleSystem::granularPass(bool stabilising, const ParallelFor& parallel) {
  float *px = m_px.data(), *py = m_py.data(), *pz = m_pz.data();
  float *qx = m_qx.data(), *qy = m_qy.data(), *qz = m_qz.data();
  // The positions this pass moves: the predicted ones, or (stabilising) the start.
  float *ox = stabilising ? px : qx, *oy = stabilising ? py : qy, *oz = stabilising ? pz : qz;
  // A compact working copy for the neighbours' reads: half a cache line a grain.
  m_grains.resize(size_t(m_n));
  Grain* g = m_grains.data();
  forBlocks(parallel, [&](int b, int e) {
    for (int i = b; i < e; ++i) g[i] = {ox[i], oy[i], oz[i], 0, px[i], py[i], pz[i], 0};
  });
  const uint32_t* nbr = m_nbr.data();
  const uint8_t* count = m_nbrCount.data();
  const uint32_t* id = m_id.data();
  const size_t stride = size_t(m_stride);
  const float d = m_spacing, d2 = d * d, tiny = 1e-12f * d2, floor = m_radius;
  const float mus = float(m_def.friction), muk = float(m_def.kineticFriction),
              minLoad = kGrainLoad * m_minLoad;
  const float shock = kGrainShock / d, weight0 = kGrainWeight * d;
  const bool friction = !stabilising && mus > 0, ground = m_ground;
  auto solve = [&](uint32_t i) {
    Grain& gi = g[i];
    const float x0 = gi.x, y0 = gi.y, z0 = gi.z, pix = gi.px, piy = gi.py, piz = gi.pz;
    float x = x0, y = y0, z = z0, ax = 0, ay = 0, az = 0, wsum = 0;
    const uint32_t* nb = nbr + size_t(i) * stride;
    for (int k = 0, n = count[i]; k < n; ++k) {
      const uint32_t j = nb[k];
      const Grain& gj = g[j];
      // A neighbour already solved in this pass (below, or earlier in the order): i is
      // projected out of it at once, from where i is now (Gauss-Seidel). One not solved yet:
      // from where both were (Jacobi), into the mean weighted by depth.
      const bool done = gj.done != 0;
      const float xs = done ? x : x0, ys = done ? y : y0, zs = done ? z : z0;
      const float dx = xs - gj.x, dy = ys - gj.y, dz = zs - gj.z;
      const float r2 = dx * dx + dy * dy + dz * dz;
      if (!(r2 < d2)) continue;
      // The normal, from j to i. Grains that passed each other's centre since the step's start
      // (fast, head on) are pushed back the way they came; coincident ones apart along z (the
      // later created one up).
      const float sx = pix - gj.px, sy = piy - gj.py, sz = piz - gj.pz;
      const float along = dx * sx + dy * sy + dz * sz;
      float ux, uy, uz, r;
      if (along > 0 && r2 > tiny) [[likely]] {
        r = std::sqrt(r2);
        const float inv = 1.0f / r;
        ux = dx * inv;
        uy = dy * inv;
        uz = dz * inv;
      } else if (const float s2 = sx * sx + sy * sy + sz * sz; s2 > tiny) {
        const float inv = 1.0f / std::sqrt(s2);
        ux = sx * inv;
        uy = sy * inv;
        uz = sz * inv;
        r = along * inv;
      } else {
        ux = uy = 0;
        uz = id[i] > id[j] ? 1.0f : -1.0f;
        r = dz * uz;
      }
      // Non-penetration, |xi - xj| >= d. Shock propagation (mass scaling by height): the upper
      // grain takes the larger share, all of it from 0.4 spacings above.
      const float depth = d - r, share = std::clamp(0.5f + shock * dz, 0.0f, 1.0f), sd = share * depth;
      float cx = sd * ux, cy = sd * uy, cz = sd * uz;
      if (friction) {
        // Friction (6.1): the pair's relative motion over the step, along the contact, undone
        // (static: below mus times the depth) or reduced by muk times the depth (kinetic).
        const float rx = (xs - pix) - (gj.x - gj.px), ry = (ys - piy) - (gj.y - gj.py),
                    rz = (zs - piz) - (gj.z - gj.pz);
        const float rn = rx * ux + ry * uy + rz * uz;
        const float tx = rx - rn * ux, ty = ry - rn * uy, tz = rz - rn * uz;
        const float t2 = tx * tx + ty * ty + tz * tz, load = std::max(depth, minLoad);
        float f = share;
        if (t2 > (mus * load) * (mus * load)) f *= std::min(muk * load / std::sqrt(t2), 1.0f);
        cx -= f * tx;
        cy -= f * ty;
        cz -= f * tz;
      }
      if (done) {
        x += cx;
        y += cy;
        z += cz;
      } else {
        const float w = sd + weight0;
        ax += w * cx;
        ay += w * cy;
        az += w * cz;
        wsum += w;
      }
    }
    if (wsum > 0) {
      const float k = 1.0f / wsum;
      x += ax * k;
      y += ay * k;
      z += az * k;
    }
    if (ground && z < floor) z = floor;
    gi.x = x;
    gi.y = y;
    gi.z = z;
    gi.done = 1;
  };
  const uint32_t* order = m_order.data();
  const uint32_t* columnStart = m_orderColumn.data();
  for (int colour = 0; colour < 4; ++colour) {
    const int c0 = m_orderColour[colour], n = m_orderColour[colour + 1] - c0;
    auto column = [&](int c) {
      const uint32_t kb = columnStart[c0 + c], ke = columnStart[c0 + c + 1];
      for (uint32_t k = kb; k < ke; ++k) {
        // The order jumps about memory: fetch the lists and the neighbours' data ahead.
        if (k + kAhead < ke) {
          __builtin_prefetch(nbr + size_t(order[k + kAhead]) * stride);
          __builtin_prefetch(g + order[k + kAhead]);
        }
        if (k + kNear < ke) {
          const uint32_t next = order[k + kNear];
          const uint32_t* nn = nbr + size_t(next) * stride;
          for (int q = 0, m = count[next]; q < m; ++q) __builtin_prefetch(g + nn[q]);
        }
        solve(order[k]);
      }
    };
    if (parallel && n > 1)
      parallel(n, column);
    else
      for (int c = 0; c < n; ++c) column(c);
  }
  const float *vx = m_vx.data(), *vy = m_vy.data(), *vz = m_vz.data(), dt = m_dt;
  forBlocks(parallel, [&](int b, int e) {
    for (int i = b; i < e; ++i) {
      const float ex = g[i].x - ox[i], ey = g[i].y - oy[i], ez = g[i].z - oz[i];
      ox[i] = g[i].x;
      oy[i] = g[i].y;
      oz[i] = g[i].z;
      if (!stabilising) continue;
      // The predicted positions move alike, and the motion into the overlap just removed is
      // taken out, up to its size (an inelastic contact: a grain pressed into a pile stops
      // instead of keeping the speed the overlap came from).
      const float e2 = ex * ex + ey * ey + ez * ez;
      float f = 1.0f;
      if (e2 > 0) {
        const float into = -(vx[i] * ex + vy[i] * ey + vz[i] * ez) * dt;  // along e, times |e|
        if (into > 0) f += std::min(into / e2, 1.0f);
      }
      qx[i] += f * ex;
      qy[i] += f * ey;
      qz[i] += f * ez;
    }
  });
}

void ParticleSystem::wallTerm(float sd, float& share, float& slope) const {
  float x = sd * (float(kWallTable) / m_h);
  if (!(x > 0)) x = 0;  // inside: as at the surface (the contact pushes it out)
  if (x >= float(kWallTable)) {
    share = slope = 0;
    return;
  }
  const int k = int(x);
  const float f = x - float(k);
  share = m_wallShare[k] + f * (m_wallShare[k + 1] - m_wallShare[k]);
  slope = m_wallSlope[k] + f * (m_wallSlope[k + 1] - m_wallSlope[k]);
}

void ParticleSystem::applyAndCollide(float dt, bool move, bool last, const ColliderSet& colliders,
                                     const ParallelFor& parallel) {
  float *qx = m_qx.data(), *qy = m_qy.data(), *qz = m_qz.data();
  const float *px = m_px.data(), *py = m_py.data(), *pz = m_pz.data();
  const float *dxi = m_dx.data(), *dyi = m_dy.data(), *dzi = m_dz.data();
  const uint32_t* cell = m_cell.data();
  const uint32_t* shapeStart = m_cellShapeStart.data();
  const int32_t* shapes = m_cellShapes.data();
  int32_t* touchBody = m_touchBody.data();
  float* touch = m_touch.data();
  float *wallS = m_wallS.data(), *wallGx = m_wallGx.data(), *wallGy = m_wallGy.data(),
        *wallGz = m_wallGz.data();
  float* slotG = m_slotG.data();
  const bool granular = m_def.kind == ParticleDef::Kind::Debris;
  const bool fluid = !granular;  // the bodies' share of density
  ContactParams cp;
  cp.radius = m_radius;
  cp.dt = dt;
  cp.mus = float(m_def.friction);
  cp.muk = float(m_def.kineticFriction);
  cp.friction = m_def.friction > 0;
  cp.minLoad = granular ? m_minLoad : 0.0f;
  const float reach = m_h;  // particles feel bodies within the kernel
  const float r = m_radius;
  // Grains resting on a surface may sit a little off it (pushed up by the grains beside them
  // since the last contact): they still touch it for friction.
  const float touchAt = granular ? kGrainTouch * m_radius : m_radius;
  const float still[3] = {0, 0, 0};
  // Whether x is in a fixed shape of the list (but `skip`) or under the ground.
  auto blocked = [&](const float* x, int skip, const int32_t* list, int n) {
    if (colliders.ground && x[2] < 0.9f * r) return true;
    for (int k = 0; k < n; ++k) {
      const ColliderShape& t = colliders.shapes[size_t(list[k])];
      if (k != skip && !t.dynamic && shapeSignedDistance(colliders, t, x, false) < 0.9f * r) return true;
    }
    return false;
  };
  // Whether x is at least half a radius off every fixed shape of the list, and (path) the way
  // from `from` to x crosses none.
  auto clear = [&](const float* x, const float* from, const int32_t* list, int n) {
    for (int k = 0; k < n; ++k) {
      const ColliderShape& t = colliders.shapes[size_t(list[k])];
      if (t.dynamic) continue;
      if (shapeSignedDistance(colliders, t, x, true) < 0.5f * r) return false;
      if (from && segmentEnters(colliders, t, from, x, 0.25f * r)) return false;
    }
    return true;
  };
  forBlocks(parallel, [&](int b, int e) {
    for (int i = b; i < e; ++i) {
      float q[3] = {qx[i], qy[i], qz[i]};
      if (move) {
        q[0] += dxi[i];
        q[1] += dyi[i];
        q[2] += dzi[i];
      }
      const float p[3] = {px[i], py[i], pz[i]};
      float ws = 0, wg[3] = {0, 0, 0}, sg[6] = {0, 0, 0, 0, 0, 0};
      // Out of the ground first: a particle below it and under a wall would otherwise leave the
      // wall through its bottom face and come up inside it.
      if (colliders.ground && q[2] < touchAt) groundContact(cp, p, q);
      const uint32_t c = cell[i];
      const int32_t* list = shapes + shapeStart[c];
      const int n = int(shapeStart[c + 1] - shapeStart[c]);
      // Moving bodies first, fixed ones last: a particle squeezed between a body and a wall ends
      // up out of the wall (and pushes the body away) rather than through the wall.
      bool anyFixed = false;
      for (int k = 0; k < n; ++k) {
        const ColliderShape& shape = colliders.shapes[size_t(list[k])];
        if (!shape.dynamic) {
          anyFixed = true;
          continue;
        }
        float sd, nrm[3], push[3] = {0, 0, 0};
        if (!shapeDistance(colliders, shape, p, q, reach, sd, nrm)) continue;
        if (sd < touchAt) {
          shapeContact(cp, colliders, shape, p, sd, nrm, q, push);
          sd = std::max(sd, cp.radius);
        }
        float share = 0, slope = 0;
        if (fluid) {
          wallTerm(sd, share, slope);
          ws += share;
          for (int a = 0; a < 3; ++a) wg[a] += slope * nrm[a];
        }
        // Remember the push for the body: the particle's correction and its moment about the
        // body's centre of mass, and (fluids) the body's share of the density gradient.
        int slot = touchBody[2 * i] == shape.body ? 0 : touchBody[2 * i + 1] == shape.body ? 1 : -1;
        if (slot < 0) slot = touchBody[2 * i] < 0 ? 0 : touchBody[2 * i + 1] < 0 ? 1 : -1;
        if (slot < 0) continue;  // a third body at one particle: rare, left out
        float* acc = touch + 12 * size_t(i) + 6 * size_t(slot);
        if (touchBody[2 * i + slot] < 0) {
          touchBody[2 * i + slot] = shape.body;
          for (int a = 0; a < 6; ++a) acc[a] = 0;
        }
        for (int a = 0; a < 3; ++a) sg[3 * slot + a] += slope * nrm[a];
        const ColliderBody& body = colliders.bodies[size_t(shape.body)];
        const float lx = q[0] - float(body.com[0]), ly = q[1] - float(body.com[1]),
                    lz = q[2] - float(body.com[2]);
        acc[0] += push[0];
        acc[1] += push[1];
        acc[2] += push[2];
        acc[3] += ly * push[2] - lz * push[1];
        acc[4] += lz * push[0] - lx * push[2];
        acc[5] += lx * push[1] - ly * push[0];
      }
      if (anyFixed) {
        // The fixed shapes as one solid (particles/particle_walls.h): out of each shape q is in,
        // the shortest way it came in that lands in no other (else the shortest way it came in;
        // else the shortest), over a few passes for corners where several meet.
        uint64_t pushed = 0;  // the fixed shapes (the list's first 64) that pushed, for friction
        for (int pass = 0; pass < 4; ++pass) {
          bool moved = false;
          for (int k = 0; k < n; ++k) {
            const ColliderShape& shape = colliders.shapes[size_t(list[k])];
            if (shape.dynamic || shapeSignedDistance(colliders, shape, q, false) >= 0.999f * r) continue;
            int bestRank = 4;
            float bestCost = 0, best[3] = {q[0], q[1], q[2]}, bestN[3] = {0, 0, 1};
            shapeExits(colliders, shape, p, q, r,
                       [&](const float* x, const float* nn, float cost, bool entry) {
                         const int rank = (entry ? 0 : 2) + (blocked(x, k, list, n) ? 1 : 0);
                         if (rank > bestRank || (rank == bestRank && cost >= bestCost)) return;
                         bestRank = rank;
                         bestCost = cost;
                         for (int a = 0; a < 3; ++a) {
                           best[a] = x[a];
                           bestN[a] = nn[a];
                         }
                       });
            if (bestRank == 4) continue;
            float push[3] = {best[0] - q[0], best[1] - q[1], best[2] - q[2]};
            for (int a = 0; a < 3; ++a) q[a] = best[a];
            contactFriction(cp, p, bestN, still, bestCost, q, push);
            if (k < 64) pushed |= uint64_t(1) << k;
            moved = true;
          }
          if (!moved) break;
        }
        // Their wall terms at the new position, and friction where grains rest on them.
        for (int k = 0; k < n; ++k) {
          const ColliderShape& shape = colliders.shapes[size_t(list[k])];
          if (shape.dynamic) continue;
          float sd, nrm[3], push[3];
          if (!shapeDistance(colliders, shape, p, q, reach, sd, nrm)) continue;
          if (sd < touchAt && !(k < 64 && (pushed >> k) & 1)) {
            shapeContact(cp, colliders, shape, p, sd, nrm, q, push);
            sd = std::max(sd, cp.radius);
          }
          if (fluid) {
            float share = 0, slope = 0;
            wallTerm(sd, share, slope);
            ws += share;
            for (int a = 0; a < 3; ++a) wg[a] += slope * nrm[a];
          }
        }
      }
      if (colliders.ground) {  // last, so no body pushes a particle under the ground
        if (q[2] < touchAt) groundContact(cp, p, q);
        if (fluid && q[2] < reach) {
          float share, slope;
          wallTerm(q[2], share, slope);
          ws += share;
          wg[2] += slope;
        }
      }
      if (last) {
        // The guard: the step ends off every fixed shape and its path crosses none (checked
        // against the shapes near its end and near its start), else the particle stays where
        // it started (when that was clear: a particle placed in a wall is only pushed out).
        const int pc = int((cellCoord(p[2], m_origin[2], m_invCell, m_dims[2]) * m_dims[1] +
                            cellCoord(p[1], m_origin[1], m_invCell, m_dims[1])) *
                               m_dims[0] +
                           cellCoord(p[0], m_origin[0], m_invCell, m_dims[0]));
        const int32_t* plist = shapes + shapeStart[pc];
        const int pn = uint32_t(pc) == c ? 0 : int(shapeStart[pc + 1] - shapeStart[pc]);
        if ((n || pn) && !(clear(q, p, list, n) && clear(q, p, plist, pn)) && clear(p, nullptr, list, n) &&
            clear(p, nullptr, plist, pn)) {
          for (int a = 0; a < 3; ++a) q[a] = p[a];
        }
      }
      if (fluid) {
        wallS[i] = ws;
        wallGx[i] = wg[0];
        wallGy[i] = wg[1];
        wallGz[i] = wg[2];
        for (int a = 0; a < 6; ++a) slotG[6 * size_t(i) + size_t(a)] = sg[a];
      }
      qx[i] = q[0];
      qy[i] = q[1];
      qz[i] = q[2];
    }
  });
}

void ParticleSystem::advance(float dt, const ParallelFor& parallel) {
  const float *px = m_px.data(), *py = m_py.data(), *pz = m_pz.data();
  float *vx = m_vx.data(), *vy = m_vy.data(), *vz = m_vz.data();
  const float *qx = m_qx.data(), *qy = m_qy.data(), *qz = m_qz.data();
  const float inv = 1.0f / dt;
  forBlocks(parallel, [&](int b, int e) {
    for (int i = b; i < e; ++i) {
      vx[i] = (qx[i] - px[i]) * inv;
      vy[i] = (qy[i] - py[i]) * inv;
      vz[i] = (qz[i] - pz[i]) * inv;
    }
  });
  std::swap(m_px, m_qx);
  std::swap(m_py, m_qy);
  std::swap(m_pz, m_qz);
}

void ParticleSystem::finish(float dt, const ParallelFor& parallel) {
  advance(dt, parallel);
  float *vx = m_vx.data(), *vy = m_vy.data(), *vz = m_vz.data();
  const float *qx = m_px.data(), *qy = m_py.data(), *qz = m_pz.data();  // the positions at the end
  const bool xsph = m_def.kind == ParticleDef::Kind::Fluid && m_def.viscosity > 0;
  if (xsph) {
    // XSPH: each velocity moves towards its neighbours' kernel-weighted mean (into the
    // correction arrays, so every particle reads the velocities before the pass).
    const uint32_t* nbr = m_nbr.data();
    const uint8_t* count = m_nbrCount.data();
    float *ox = m_dx.data(), *oy = m_dy.data(), *oz = m_dz.data();
    const float c = float(m_def.viscosity) * m_poly6, h2 = m_h * m_h;
    forBlocks(parallel, [&](int b, int e) {
      for (int i = b; i < e; ++i) {
        const float xi = qx[i], yi = qy[i], zi = qz[i];
        const float ux = vx[i], uy = vy[i], uz = vz[i];
        const uint32_t* nb = nbr + size_t(i) * kMaxNeighbours;
        float ax = 0, ay = 0, az = 0;
        for (int k = 0, n = count[i]; k < n; ++k) {
          const uint32_t j = nb[k];
          const float dx = xi - qx[j], dy = yi - qy[j], dz = zi - qz[j];
          const float r2 = dx * dx + dy * dy + dz * dz;
          const float t = std::max(h2 - r2, 0.0f), w = t * t * t;
          ax += (vx[j] - ux) * w;
          ay += (vy[j] - uy) * w;
          az += (vz[j] - uz) * w;
        }
        ox[i] = ux + c * ax;
        oy[i] = uy + c * ay;
        oz[i] = uz + c * az;
      }
    });
    std::swap(m_vx, m_dx);
    std::swap(m_vy, m_dy);
    std::swap(m_vz, m_dz);
  }
}

void ParticleSystem::reducePushes(float dt, int substeps, const ColliderSet& colliders) {
  // In particle order on this thread: the same sums whatever the thread count.
  std::vector<BodyPush>& out = m_pushes;
  // The particle's corrections as a force on the body over the step: a correction in a substep
  // is an impulse m dx / (dt / substeps).
  const double k = -m_mass * substeps / (double(dt) * dt);
  for (int i = 0; i < m_n; ++i)
    for (int s = 0; s < 2; ++s) {
      const int body = m_touchBody[size_t(2 * i + s)];
      if (body < 0) continue;
      BodyPush* p = nullptr;
      for (BodyPush& q : out)
        if (q.part == colliders.bodies[size_t(body)].part) p = &q;
      if (!p) {
        out.push_back({});
        p = &out.back();
        p->part = colliders.bodies[size_t(body)].part;
        const ColliderBody& cb = colliders.bodies[size_t(body)];
        p->com = Vec3(cb.com[0], cb.com[1], cb.com[2]);
      }
      const float* acc = m_touch.data() + 12 * size_t(i) + 6 * size_t(s);
      p->force += k * Vec3(acc[0], acc[1], acc[2]);
      p->torque += k * Vec3(acc[3], acc[4], acc[5]);
    }
}

void ParticleSystem::bounds(Vec3& lo, Vec3& hi) const {
  lo = Vec3::Constant(std::numeric_limits<double>::max());
  hi = -lo;
  bool any = false;
  for (int i = 0; i < m_n; ++i) {
    const Vec3 p(m_px[size_t(i)], m_py[size_t(i)], m_pz[size_t(i)]);
    if (!p.allFinite()) continue;
    lo = lo.cwiseMin(p);
    hi = hi.cwiseMax(p);
    any = true;
  }
  if (!any) lo = hi = Vec3::Zero();
}

Vec3 ParticleSystem::meanVelocity() const {
  Vec3 s = Vec3::Zero();
  int n = 0;
  for (int i = 0; i < m_n; ++i) {
    const Vec3 v(m_vx[size_t(i)], m_vy[size_t(i)], m_vz[size_t(i)]);
    if (!v.allFinite()) continue;
    s += v;
    ++n;
  }
  return n ? Vec3(s / n) : Vec3::Zero();
}

int ParticleSystem::nanCount() const {
  int n = 0;
  for (int i = 0; i < m_n; ++i) {
    const size_t k = size_t(i);
    if (!std::isfinite(m_px[k]) || !std::isfinite(m_py[k]) || !std::isfinite(m_pz[k]) ||
        !std::isfinite(m_vx[k]) || !std::isfinite(m_vy[k]) || !std::isfinite(m_vz[k]))
      ++n;
  }
  return n;
}

uint64_t ParticleSystem::stateHash() const {
  uint64_t h = 0xcbf29ce484222325ull;
  for (const std::vector<float>* v : {&m_px, &m_py, &m_pz, &m_vx, &m_vy, &m_vz})
    for (float f : *v) {
      uint32_t bits;
      std::memcpy(&bits, &f, 4);
      for (int k = 0; k < 4; ++k) h = (h ^ ((bits >> (8 * k)) & 0xFFu)) * 0x100000001b3ull;
    }
  return h;
}

}  // namespace rm3d
