// Rigid bodies kept side by side in memory. Bullet's per-substep passes (integration, bounding
// boxes, islands, the hinge loops) touch every body once; allocated one at a time between a
// world's other allocations (each module's Lua state among them), 40,000 bodies lie scattered
// over hundreds of megabytes and every pass streams them from memory. Here they come from chunks
// of 256 in the order they are made, and a removed body's slot is reused by the next one.
#pragma once

#include <BulletDynamics/Dynamics/btRigidBody.h>
#include <LinearMath/btAlignedAllocator.h>

#include <cstddef>
#include <new>
#include <vector>

namespace rm3d {

class BodyPool {
 public:
  BodyPool() = default;
  BodyPool(const BodyPool&) = delete;
  BodyPool& operator=(const BodyPool&) = delete;
  ~BodyPool() {
    for (void* c : m_chunks) btAlignedFree(c);
  }

  /// A body made in the pool (give it back with destroy, not delete).
  btRigidBody* make(const btRigidBody::btRigidBodyConstructionInfo& ci) {
    void* slot;
    if (!m_free.empty()) {
      slot = m_free.back();
      m_free.pop_back();
    } else {
      if (m_chunks.empty() || m_used == kChunk) {
        void* chunk = btAlignedAlloc(kChunk * kSlot, 16);
        if (!chunk) throw std::bad_alloc();
        m_chunks.push_back(chunk);
        m_used = 0;
      }
      slot = static_cast<char*>(m_chunks.back()) + m_used++ * kSlot;
    }
    return new (slot) btRigidBody(ci);
  }

  void destroy(btRigidBody* rb) {
    if (!rb) return;
    rb->~btRigidBody();
    m_free.push_back(rb);
  }

 private:
  static constexpr size_t kSlot = (sizeof(btRigidBody) + 15) & ~size_t(15);
  static constexpr size_t kChunk = 256;
  std::vector<void*> m_chunks;
  std::vector<void*> m_free;
  size_t m_used = 0;
};

}  // namespace rm3d
