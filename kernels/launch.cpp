#include "launch.hpp"

#include <sys/mman.h>

#include <cstdlib>
#include <new>
#include <stdexcept>
#include <string>

namespace tresca {

namespace {
constexpr std::size_t kHugePage = std::size_t(2) << 20;
constexpr std::size_t kHugeFrom = std::size_t(1) << 20;
}  // namespace

void* field_allocate(std::size_t bytes) {
  if (bytes < kHugeFrom) return ::operator new(bytes);
  const std::size_t rounded = (bytes + kHugePage - 1) / kHugePage * kHugePage;
  void* p = std::aligned_alloc(kHugePage, rounded);
  if (!p) throw std::bad_alloc();
  madvise(p, rounded, MADV_HUGEPAGE);  // advice only: where THP is off it fails harmlessly
  return p;
}

void field_deallocate(void* p, std::size_t bytes) noexcept {
  if (bytes < kHugeFrom)
    ::operator delete(p);
  else
    std::free(p);
}

namespace {
bool on_device = false;
int device() { return omp_get_num_devices() > 0 ? omp_get_default_device() : omp_get_initial_device(); }
}  // namespace

bool offload_built() {
#ifdef TRESCA_OFFLOAD
  return true;
#else
  return false;
#endif
}

bool launch_on_device() { return on_device; }

void set_launch_on_device(bool on) {
  if (on && !offload_built())
    throw std::invalid_argument("this build has no device backend (configure with -DTRESCA_OFFLOAD=ON)");
  on_device = on;
}

void* device_allocate(std::size_t bytes) {
  void* p = omp_target_alloc(bytes, device());
  if (!p && bytes) throw std::bad_alloc();
  return p;
}

void device_free(void* p) noexcept {
  if (p) omp_target_free(p, device());
}

void copy_to_device(void* to, const void* from, std::size_t bytes) {
  if (omp_target_memcpy(to, from, bytes, 0, 0, device(), omp_get_initial_device()) != 0)
    throw std::runtime_error("copy to the device failed");
}

void copy_from_device(void* to, const void* from, std::size_t bytes) {
  if (omp_target_memcpy(to, from, bytes, 0, 0, omp_get_initial_device(), device()) != 0)
    throw std::runtime_error("copy from the device failed");
}

std::string device_description() {
  const int n = omp_get_num_devices();
  if (n == 0) return offload_built() ? "none: target regions run on the host" : "none (built without offload)";
  return "device " + std::to_string(omp_get_default_device()) + " of " + std::to_string(n) + " (OpenMP offload)";
}

}  // namespace tresca
