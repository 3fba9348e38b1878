// Memory for objects that every substep passes over, side by side: rigid bodies (PhysicsWorld),
// contact manifolds and pair algorithms (TaskDispatcher). Bullet keeps a fixed pool of manifolds
// and of algorithms, made whole with the world, and takes from the heap past it: at thousands of
// modules most lay scattered among the other allocations (each module's Lua state among them),
// and every substep's pass over the pairs read each from memory. Here slots come from blocks that
// never move, made as they are needed (nothing is written in a block before it is used: a small
// world pays for what it uses); a slot given back is the next one taken. Each slot starts with a
// tag, so anything larger than a slot can come from the heap and be told apart when given back.
#pragma once

#include <LinearMath/btAlignedAllocator.h>

#include <cstddef>
#include <cstdint>
#include <new>
#include <vector>

namespace rm3d {

class SlotPool {
 public:
  /// Slots of `size` bytes (16-byte aligned), `perBlock` to a block.
  SlotPool(size_t size, size_t perBlock)
      : m_stride(kHeader + ((size + 15) & ~size_t(15))), m_perBlock(perBlock) {}
  SlotPool(const SlotPool&) = delete;
  SlotPool& operator=(const SlotPool&) = delete;
  ~SlotPool() {
    for (void* b : m_blocks) btAlignedFree(b);
  }

  /// `size` bytes, 16-byte aligned: a slot if it fits, else from the heap.
  void* take(size_t size) {
    char* p;
    if (size + kHeader > m_stride) {
      p = static_cast<char*>(btAlignedAlloc(size + kHeader, 16));
      if (!p) throw std::bad_alloc();
      *reinterpret_cast<uint64_t*>(p) = kHeap;
    } else if (!m_free.empty()) {
      p = m_free.back();
      m_free.pop_back();
    } else {
      if (m_blocks.empty() || m_used == m_perBlock) {
        void* b = btAlignedAlloc(m_perBlock * m_stride, 16);
        if (!b) throw std::bad_alloc();
        m_blocks.push_back(b);
        m_used = 0;
      }
      p = static_cast<char*>(m_blocks.back()) + m_used++ * m_stride;
      *reinterpret_cast<uint64_t*>(p) = kSlot;
    }
    return p + kHeader;
  }

  /// Gives back what take returned.
  void give(void* mem) {
    if (!mem) return;
    char* p = static_cast<char*>(mem) - kHeader;
    if (*reinterpret_cast<const uint64_t*>(p) == kHeap)
      btAlignedFree(p);
    else
      m_free.push_back(p);
  }

 private:
  static constexpr size_t kHeader = 16;  // the tag (keeps the slot 16-byte aligned)
  static constexpr uint64_t kSlot = 0x534c4f54, kHeap = 0x48454150;
  size_t m_stride;
  size_t m_perBlock;
  std::vector<void*> m_blocks;
  std::vector<char*> m_free;
  size_t m_used = 0;
};

}  // namespace rm3d
