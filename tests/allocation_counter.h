// Counts heap allocations made by the current thread, to prove that hot paths allocate nothing.
// The global operator new/delete replacements live once in allocation_counter.cc for the whole
// test binary; test files must not define their own.
#pragma once

#include <cstddef>

// Under Address- or ThreadSanitizer: GCC defines __SANITIZE_ADDRESS__ / __SANITIZE_THREAD__,
// clang answers __has_feature.
#if defined(__SANITIZE_ADDRESS__) || defined(__SANITIZE_THREAD__)
#define TAUT_TESTS_SANITIZED 1
#elif defined(__has_feature)
#if __has_feature(address_sanitizer) || __has_feature(thread_sanitizer)
#define TAUT_TESTS_SANITIZED 1
#endif
#endif

// 1 when malloc/calloc/realloc are counted as well as operator new: on glibc, except under
// Address- or ThreadSanitizer, whose runtimes own malloc and call it before they are initialized.
#if defined(__GLIBC__) && !defined(TAUT_TESTS_SANITIZED)
#define TAUT_TESTS_COUNT_MALLOC 1
#else
#define TAUT_TESTS_COUNT_MALLOC 0
#endif

namespace taut::testing {

// Number of operator new calls made by this thread since the program started.
std::size_t AllocationCount();

// Counts the allocations made while it is alive: `ScopedAllocationCounter c; ...; c.count()`.
class ScopedAllocationCounter {
 public:
  ScopedAllocationCounter() : start_(AllocationCount()) {}
  std::size_t count() const { return AllocationCount() - start_; }

 private:
  std::size_t start_;
};

}  // namespace taut::testing
