// Every heap allocation of a benchmark program, counted in femb_allocations: malloc, calloc and
// realloc replaced by wrappers around glibc's own (the program's definitions interpose the
// library's). Include it in one source file of a program (it defines them). Not under
// AddressSanitizer, which has malloc of its own (the count then stays 0). femb_on_allocation,
// when set, is called on every allocation (not from within itself): the allocation test's trace
// mode prints the call stack of each (FEMB_ALLOCATION_TRACE=1).
#pragma once

#include <atomic>
#include <cstddef>

#if defined(__has_feature)
#if __has_feature(address_sanitizer)
#define FEMB_NO_MALLOC_COUNT
#endif
#endif
#ifdef __SANITIZE_ADDRESS__
#define FEMB_NO_MALLOC_COUNT
#endif
static std::atomic<long> femb_allocations{0};
static void (*femb_on_allocation)() = nullptr;
static thread_local bool femb_in_allocation_hook = false;
static inline void femb_count_allocation() {
  femb_allocations.fetch_add(1, std::memory_order_relaxed);
  if (femb_on_allocation && !femb_in_allocation_hook) {
    femb_in_allocation_hook = true;
    femb_on_allocation();
    femb_in_allocation_hook = false;
  }
}
#ifndef FEMB_NO_MALLOC_COUNT
extern "C" {
void* __libc_malloc(std::size_t);
void* __libc_calloc(std::size_t, std::size_t);
void* __libc_realloc(void*, std::size_t);
void __libc_free(void*);
__attribute__((visibility("default"))) void* malloc(std::size_t size) {
  femb_count_allocation();
  return __libc_malloc(size);
}
__attribute__((visibility("default"))) void* calloc(std::size_t n, std::size_t size) {
  femb_count_allocation();
  return __libc_calloc(n, size);
}
__attribute__((visibility("default"))) void* realloc(void* p, std::size_t size) {
  femb_count_allocation();
  return __libc_realloc(p, size);
}
__attribute__((visibility("default"))) void free(void* p) { __libc_free(p); }
}
#endif
