// A vector allocator that leaves elements of trivial types unset when the
// vector makes them without a value (vector(n), resize(n)): the memory's
// pages are then first written, and so faulted in and zeroed by the
// kernel, by whichever threads fill the elements, not all on the one
// thread that made the vector. For buffers of hundreds of megabytes that
// a build fills on all its threads (the stored triangles).
#pragma once
#include <memory>
#include <type_traits>
#include <utility>
#include <vector>

namespace meshcast {

template <class T>
struct FirstTouch : std::allocator<T> {
  static_assert(std::is_trivially_default_constructible_v<T>, "elements left unset must be trivial");
  template <class U>
  struct rebind {
    using other = FirstTouch<U>;
  };
  FirstTouch() = default;
  template <class U>
  FirstTouch(const FirstTouch<U>&) noexcept {}
  template <class U>
  void construct(U* p) noexcept {
    ::new (static_cast<void*>(p)) U;  // default-initialized: no value written
  }
  template <class U, class... Args>
  void construct(U* p, Args&&... args) {
    ::new (static_cast<void*>(p)) U(std::forward<Args>(args)...);
  }
};

// Elements a build writes all of, on its threads, before it reads any.
template <class T>
using FilledVector = std::vector<T, FirstTouch<T>>;

}  // namespace meshcast
