// Each Lua state's small objects (up to 512 bytes: tables, closures, short strings, upvalues) in
// blocks of its own, by size class, instead of the process's heap. With thousands of VMs stepped
// one after the other, a VM's objects otherwise lay spread among every other VM's and among the
// physics' own allocations (bodies' proxies, shapes), so each behaviour call read its state from
// cold memory and each physics pass read past the VMs' objects. Lua tells the allocator a block's
// old size, so a freed object goes back to its class's list without a header; the lists are taken
// last-in first-out. Larger blocks (arrays, stacks, long strings) come from the heap.
// Under AddressSanitizer everything comes from the heap, so that ASan still sees the VMs' misuses.
#pragma once

#include <algorithm>
#include <cstddef>
#include <cstdlib>
#include <cstring>
#include <vector>

#if defined(__SANITIZE_ADDRESS__)
#define RM3D_VM_HEAP_POOLED 0
#elif defined(__has_feature)
#if __has_feature(address_sanitizer)
#define RM3D_VM_HEAP_POOLED 0
#endif
#endif
#ifndef RM3D_VM_HEAP_POOLED
#define RM3D_VM_HEAP_POOLED 1
#endif

namespace rm3d {

class VmHeap {
 public:
  static constexpr size_t kGrain = 16;    ///< class size step (and the blocks' alignment)
  static constexpr size_t kClasses = 32;  ///< classes of 16 to 512 bytes
  static constexpr size_t kLargest = kGrain * kClasses;

  /// False under AddressSanitizer: every block then comes from the heap.
  static constexpr bool pooled() { return RM3D_VM_HEAP_POOLED != 0; }

  VmHeap() = default;
  VmHeap(const VmHeap&) = delete;
  VmHeap& operator=(const VmHeap&) = delete;
  ~VmHeap() {
    for (void* b : m_blocks) std::free(b);
  }

  /// As lua_Alloc: osize is the block's size (0 when ptr is null); nsize 0 frees. Null when out of
  /// memory (the block is then untouched).
  void* realloc(void* ptr, size_t osize, size_t nsize) {
    if (!ptr) osize = 0;
    if (nsize == 0) {
      release(ptr, osize);
      return nullptr;
    }
    if (ptr && small(osize) == small(nsize) && (!small(nsize) || cls(osize) == cls(nsize)))
      return small(nsize) ? ptr : std::realloc(ptr, nsize);
    void* q = small(nsize) ? take(cls(nsize)) : std::malloc(nsize);
    if (!q) return nullptr;
    if (ptr) {
      std::memcpy(q, ptr, std::min(osize, nsize));
      release(ptr, osize);
    }
    return q;
  }

 private:
  struct Free {
    Free* next;
  };
  static bool small(size_t n) { return pooled() && n <= kLargest; }
  static size_t cls(size_t n) { return (n + kGrain - 1) / kGrain - 1; }

  void* take(size_t c) {
    if (Free* f = m_free[c]) {
      m_free[c] = f->next;
      return f;
    }
    const size_t size = (c + 1) * kGrain;
    if (m_left < size) {
      // Blocks of 2 KB at first, doubling to 32 KB: a small VM stays small. (What is left of the
      // last block, under 512 bytes, is not used.)
      const size_t bytes = std::min<size_t>(size_t(2048) << std::min<size_t>(m_blocks.size(), 4), 32768);
      void* b = std::aligned_alloc(kGrain, bytes);
      if (!b) return nullptr;
      m_blocks.push_back(b);
      m_next = static_cast<char*>(b);
      m_left = bytes;
    }
    void* p = m_next;
    m_next += size;
    m_left -= size;
    return p;
  }

  void release(void* p, size_t n) {
    if (!p) return;
    if (!small(n)) return std::free(p);
    Free* f = static_cast<Free*>(p);
    f->next = m_free[cls(n)];
    m_free[cls(n)] = f;
  }

  Free* m_free[kClasses] = {};
  char* m_next = nullptr;
  size_t m_left = 0;
  std::vector<void*> m_blocks;
};

}  // namespace rm3d
