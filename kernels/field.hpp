// Field<T>: the storage of everything the linear machinery sweeps, in the
// memory where the kernels run (kernels/launch.hpp).
//
// A Field lives in one Space: the host's memory, or the device's (a
// TRESCA_OFFLOAD build). Its place is chosen when it first gets storage:
//
//   - sized storage (Field(n), Field(n, v), resize or assign of an empty
//     Field) is made where launches run now, launch_space(): on the device
//     while launch_on_device() holds, on the host otherwise;
//   - storage filled from host data (iterators, initializer lists,
//     push_back onto an empty Field) is the host's;
//   - a copy lives where its source does; move_to(space) moves it.
//
// Kernels see only data(): device pointers are for launches. Reading or
// writing entries on the host (operator[], begin/end, front/back,
// push_back) is allowed on a host Field only, and throws std::logic_error
// on a device one: a solve that should stay on the device cannot quietly
// read through a device pointer. Code that builds data entry by entry runs
// inside a HostLaunches scope (launch.hpp) and moves its result to where
// the launches ran before (move_to). Entries are trivially copyable; new
// entries are zero (T{}).
//
// Host storage of 1 MiB or more is aligned to 2 MiB and marked
// MADV_HUGEPAGE, so where the kernel's transparent-huge-page mode is
// "madvise" (Debian's default) its first touch costs one page fault per
// 2 MiB instead of per 4 KiB (perf/RESULTS.md §0d, §0k); zeroing and
// copying it are split among the threads, so that first touch runs on
// every core (§0o).
#pragma once
#include <algorithm>
#include <cstddef>
#include <initializer_list>
#include <iterator>
#include <type_traits>
#include <utility>
#include <vector>

#include "types.hpp"

namespace tresca {

enum class Space : unsigned char { host, device };
const char* to_string(Space s);

// where new sized storage goes: Space::device while launch_on_device()
Space launch_space();
// storage in a space, and copies between any two; zero: all bytes 0
void* space_allocate(Space s, std::size_t bytes);
void space_free(Space s, void* p, std::size_t bytes) noexcept;
void space_copy(Space to_space, void* to, Space from_space, const void* from, std::size_t bytes);
void space_zero(Space s, void* p, std::size_t bytes);
[[noreturn]] void field_read_on_host(Space s);  // throws std::logic_error

// Blocks freed by Fields are kept for the next Field of the same size
// (launch.cpp: large host blocks and every device block; the memory held
// stays under held_limit_bytes, the most the live Fields ever needed plus
// a slack). What that saved so far, in one space:
struct BlockReuse {
  long long requests = 0, reused = 0;  // blocks asked for, and of them, blocks handed out again
  double reused_bytes = 0;             // their bytes: memory not faulted in (or cudaMalloc'ed) again
  double kept_bytes = 0;               // bytes kept now for reuse
  double live_bytes = 0, peak_bytes = 0;  // in live Fields now, and the most ever
  double held_limit_bytes = 0;            // live + kept stays below it (peak + slack)
};
BlockReuse block_reuse(Space s);

template <class T>
class Field {
  static_assert(std::is_trivially_copyable<T>::value, "a Field holds plain data that can be copied by bytes");

 public:
  using value_type = T;
  using size_type = std::size_t;
  using iterator = T*;
  using const_iterator = const T*;

  Field() = default;
  explicit Field(size_type n) { allocate(launch_space(), n, n); }
  Field(size_type n, const T& v) { assign(n, v); }
  template <class It, class = typename std::iterator_traits<It>::iterator_category>
  Field(It first, It last) {
    assign_host(std::vector<T>(first, last));
  }
  Field(std::initializer_list<T> l) { assign_host(std::vector<T>(l)); }
  Field(const Field& o) : space_(o.space_) {
    allocate(o.space_, o.n_, 0);
    space_copy(space_, p_, o.space_, o.p_, bytes(o.n_));
    n_ = o.n_;
  }
  Field(Field&& o) noexcept { swap(o); }
  // (into its own storage where that has o's size in o's space: no new block)
  Field& operator=(const Field& o) {
    if (this == &o) return *this;
    if (cap_ == o.n_ && cap_ > 0 && space_ == o.space_) {
      space_copy(space_, p_, o.space_, o.p_, bytes(o.n_));
      n_ = o.n_;
      return *this;
    }
    Field t(o);
    swap(t);
    return *this;
  }
  Field& operator=(Field&& o) noexcept {
    Field t(std::move(o));
    swap(t);
    return *this;
  }
  ~Field() { release(); }

  size_type size() const { return size_type(n_); }
  bool empty() const { return n_ == 0; }
  Space space() const { return space_; }
  bool on_device() const { return n_ > 0 && space_ == Space::device; }
  T* data() { return p_; }
  const T* data() const { return p_; }

  // host Fields only
  T& operator[](size_type i) { return host()[i]; }
  const T& operator[](size_type i) const { return host()[i]; }
  T* begin() { return host(); }
  T* end() { return host() + n_; }
  const T* begin() const { return host(); }
  const T* end() const { return host() + n_; }
  T& front() { return host()[0]; }
  T& back() { return host()[n_ - 1]; }
  const T& front() const { return host()[0]; }
  const T& back() const { return host()[n_ - 1]; }
  void push_back(const T& v) {
    if (cap_ == 0) space_ = Space::host;
    host();  // (refused on a device Field before it grows)
    if (n_ == cap_) reserve_in(space_, std::max<index>(16, 2 * cap_));
    host()[n_++] = v;
  }

  // n entries: the first min(n, size()) kept, new ones zero
  void resize(size_type n) {
    if (cap_ == 0) space_ = launch_space();
    if (index(n) > cap_) reserve_in(space_, index(n));
    if (index(n) > n_) space_zero(space_, p_ + n_, bytes(index(n) - n_));
    n_ = index(n);
  }
  // n entries equal to v
  void assign(size_type n, const T& v) {
    if (is_zero(v)) {
      clear();
      resize(n);
    } else {
      Field t;
      t.assign_host(std::vector<T>(n, v));
      t.move_to(cap_ == 0 ? launch_space() : space_);
      swap(t);
    }
  }
  template <class It, class = typename std::iterator_traits<It>::iterator_category>
  void assign(It first, It last) {
    Field t(first, last);
    swap(t);
  }
  void clear() { n_ = 0; }
  void swap(Field& o) noexcept {
    std::swap(p_, o.p_);
    std::swap(n_, o.n_);
    std::swap(cap_, o.cap_);
    std::swap(space_, o.space_);
  }
  // the same entries in space s
  void move_to(Space s) {
    if (s == space_) return;
    if (cap_ == 0) {
      space_ = s;
      return;
    }
    Field t;
    t.allocate(s, n_, 0);
    space_copy(s, t.p_, space_, p_, bytes(n_));
    t.n_ = n_;
    swap(t);
  }
  // a host copy of the entries, wherever they live
  std::vector<T> to_vector() const {
    std::vector<T> v(n_);
    space_copy(Space::host, v.data(), space_, p_, bytes(n_));
    return v;
  }

 private:
  static std::size_t bytes(index n) { return std::size_t(n) * sizeof(T); }
  static bool is_zero(const T& v) {
    if constexpr (std::is_arithmetic<T>::value)
      return v == T{};
    else
      return false;
  }
  T* host() const {
    if (space_ != Space::host && cap_ > 0) field_read_on_host(space_);
    return p_;
  }
  void allocate(Space s, index cap, index n) {
    space_ = s;
    cap_ = cap;
    p_ = cap > 0 ? static_cast<T*>(space_allocate(s, bytes(cap))) : nullptr;
    if (n > 0) space_zero(s, p_, bytes(n));
    n_ = n;
  }
  void reserve_in(Space s, index cap) {
    Field t;
    t.allocate(s, cap, 0);
    space_copy(s, t.p_, space_, p_, bytes(n_));
    t.n_ = n_;
    swap(t);
  }
  void assign_host(const std::vector<T>& v) {
    Field t;
    t.allocate(Space::host, index(v.size()), 0);
    std::copy(v.begin(), v.end(), t.p_);
    t.n_ = index(v.size());
    swap(t);
  }
  void release() noexcept {
    if (p_) space_free(space_, p_, bytes(cap_));
    p_ = nullptr;
    n_ = cap_ = 0;
  }

  T* p_ = nullptr;
  index n_ = 0, cap_ = 0;
  Space space_ = Space::host;
};

// host values (converted to T) in a Field where the launches run now
template <class T, class U>
Field<T> placed_field(const std::vector<U>& host) {
  Field<T> f(host.begin(), host.end());
  f.move_to(launch_space());
  return f;
}

}  // namespace tresca
