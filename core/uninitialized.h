// Arrays whose growth leaves the new elements for a parallel loop to write.
//
// std::vector value-initialises every element `resize` adds, on the calling thread: for an array
// that a parallel loop then writes in full (the light simulator's patch lists, grown as the
// wavefront splits) that is a second pass over it, and on fresh memory it is the pass that faults
// the pages in, so the kernel zeroes all of them on one core while the other waits
// (BENCHMARKS.md, issue 13, twenty-eighth part). With UninitializedAllocator `resize` adds the
// elements without writing them; the loop's threads then fault in their own shares of the pages.
//
// For implicit-lifetime types only (trivially copyable and trivially destructible, such as
// aggregates of numbers): their objects exist in the allocated storage without construction
// (C++20 [intro.object]), and an element added by `resize` holds no value until it is written.
// Everything else the allocator constructs as std::allocator does (push_back, insert, assign(n, v)
// and the range constructor copy their values as usual).
#pragma once

#include <memory>
#include <type_traits>
#include <utility>
#include <vector>

namespace eik {

template <class T>
struct UninitializedAllocator : std::allocator<T> {
  template <class U>
  struct rebind {
    using other = UninitializedAllocator<U>;
  };
  UninitializedAllocator() noexcept = default;
  template <class U>
  UninitializedAllocator(const UninitializedAllocator<U>&) noexcept {}  // NOLINT: rebinding converts implicitly

  // Value-initialisation (what `resize` asks): nothing is written.
  template <class U>
  void construct(U*) noexcept {
    static_assert(std::is_trivially_copyable_v<U> && std::is_trivially_destructible_v<U>,
                  "UninitializedAllocator: for implicit-lifetime types only");
  }
  template <class U, class... Args>
  void construct(U* p, Args&&... args) {
    ::new (static_cast<void*>(p)) U(std::forward<Args>(args)...);
  }
};

template <class T, class U>
bool operator==(const UninitializedAllocator<T>&, const UninitializedAllocator<U>&) noexcept {
  return true;
}

// A vector whose `resize` leaves the added elements unwritten (see above).
template <class T>
using UninitializedVector = std::vector<T, UninitializedAllocator<T>>;

}  // namespace eik
