// Array<T>: std::vector with a staggered start address, for the hot per-particle and per-pair
// columns.
//
// Structure-of-arrays storage reads the same index of many columns together (x[j], v[j], r[j],
// m[j], ... of one partner; or the 20 columns of a contact batch). glibc serves every
// allocation above 128 KiB with a fresh mmap, so such columns all start at the same offset in a
// page: element j of every column then falls into the same L1 cache set (4 KiB apart), more
// columns than the cache has ways evict each other, and loads and stores alias in the 4 KiB
// store-forwarding check. Measured on the 30 000-sphere scene: 85 ns per particle-step with
// page-aligned columns against 48 ns with the columns spread (bench/throughput,
// docs/performance.md). Each allocation here starts a different number of cache lines (1..63) into
// its first page.
#pragma once

#include <atomic>
#include <cstddef>
#include <new>
#include <vector>

namespace dem2d {

namespace detail {
inline constexpr std::size_t kLine = 64, kPage = 4096;
// Cache-line offset of the next allocation: 1..63, a stride coprime with 63 so consecutive
// allocations land far apart.
inline std::size_t next_stagger() {
  static std::atomic<std::size_t> counter{0};
  const std::size_t k = counter.fetch_add(1, std::memory_order_relaxed);
  return 1 + (k * 29) % 63;
}
}  // namespace detail

template <class T>
struct StaggeredAllocator {
  using value_type = T;
  StaggeredAllocator() = default;
  template <class U>
  StaggeredAllocator(const StaggeredAllocator<U>&) noexcept {}

  T* allocate(std::size_t n) {
    if (n > (static_cast<std::size_t>(-1) - detail::kPage) / sizeof(T))
      throw std::bad_array_new_length();
    const std::size_t offset = detail::next_stagger() * detail::kLine;
    std::byte* base = static_cast<std::byte*>(
        ::operator new (n * sizeof(T) + detail::kPage, std::align_val_t{detail::kLine}));
    std::byte* p = base + offset;
    reinterpret_cast<std::byte**>(p)[-1] = base;  // offset >= 64: room for the base pointer
    return reinterpret_cast<T*>(p);
  }
  void deallocate(T* p, std::size_t) noexcept {
    std::byte* base = reinterpret_cast<std::byte**>(p)[-1];
    ::operator delete (base, std::align_val_t{detail::kLine});
  }
  friend bool operator==(const StaggeredAllocator&, const StaggeredAllocator&) { return true; }
};

template <class T>
using Array = std::vector<T, StaggeredAllocator<T>>;

}  // namespace dem2d
