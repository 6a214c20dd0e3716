#include "solver/parallel.h"

#include <sched.h>

#include <algorithm>
#include <chrono>

namespace femb {
namespace {

// How long a helper looks for the next pass before it sleeps.
constexpr int kSpinMicroseconds = 200;

}  // namespace

int DefaultThreads() {
  cpu_set_t set;
  CPU_ZERO(&set);
  if (sched_getaffinity(0, sizeof set, &set) == 0) return std::max(1, CPU_COUNT(&set));
  return std::max(1, int(std::thread::hardware_concurrency()));
}

BodyThreads::BodyThreads(int threads) : ranges_(std::make_unique<Range[]>(size_t(std::max(threads, 1)))) {
  for (int i = 1; i < threads; ++i) helpers_.emplace_back([this, i] { Helper(i); });
}

BodyThreads::~BodyThreads() {
  {
    std::lock_guard<std::mutex> lock(mutex_);
    stop_ = true;
  }
  wake_.notify_all();
  for (std::thread& t : helpers_) t.join();
}

void BodyThreads::Work(Pass& pass, int thread) {
  for (int k = 0; k < pass.n_ranges; ++k) {
    Range& range = pass.ranges[(thread + k) % pass.n_ranges];  // its own range first
    for (int i = range.next.fetch_add(1); i < range.end; i = range.next.fetch_add(1)) {
      try {
        (*pass.f)(i);
      } catch (...) {
        (*pass.errors)[size_t(i)] = std::current_exception();
      }
      pass.done.fetch_add(1, std::memory_order_release);
    }
  }
}

void BodyThreads::Helper(int thread) {
  long seen = 0;
  for (;;) {
    // Passes come every few hundred microseconds in a time step: look for the next one for a
    // while before sleeping (a sleeping helper wakes 10-50 us late and finds the bodies taken).
    const auto until = std::chrono::steady_clock::now() + std::chrono::microseconds(kSpinMicroseconds);
    while (published_.load(std::memory_order_acquire) == seen && std::chrono::steady_clock::now() < until) {
      std::this_thread::yield();  // a process that shares the core runs meanwhile
    }
    Pass* pass = nullptr;
    {
      std::unique_lock<std::mutex> lock(mutex_);
      wake_.wait(lock, [&] { return stop_ || generation_ != seen; });
      if (stop_) return;
      seen = generation_;
      pass = pass_;
      if (pass) pass->users.fetch_add(1);  // the pass stays alive until users is back to 0
    }
    if (!pass) continue;  // woke after that pass had ended
    Work(*pass, thread);
    pass->users.fetch_sub(1, std::memory_order_release);
  }
}

void BodyThreads::ForEach(int n, BodyTask f) {
  if (helpers_.empty() || n <= 1) {
    for (int i = 0; i < n; ++i) f(i);
    return;
  }
  Pass pass;
  pass.f = &f;
  pass.n = n;
  errors_.assign(size_t(n), nullptr);
  pass.errors = &errors_;
  const int parts = threads();
  for (int k = 0; k < parts; ++k) {
    ranges_[size_t(k)].next.store(int(long(n) * k / parts), std::memory_order_relaxed);
    ranges_[size_t(k)].end = int(long(n) * (k + 1) / parts);
  }
  pass.ranges = ranges_.get();
  pass.n_ranges = parts;
  {
    std::lock_guard<std::mutex> lock(mutex_);
    pass_ = &pass;
    ++generation_;
    published_.store(generation_, std::memory_order_release);
  }
  wake_.notify_all();
  Work(pass, 0);
  // Only bodies a helper has begun are left: wait for them, then close the pass to latecomers
  // and wait for the helpers still holding it.
  while (pass.done.load(std::memory_order_acquire) < n) std::this_thread::yield();
  {
    std::lock_guard<std::mutex> lock(mutex_);
    pass_ = nullptr;
  }
  while (pass.users.load(std::memory_order_acquire) > 0) std::this_thread::yield();
  for (const std::exception_ptr& e : errors_) {
    if (e) std::rethrow_exception(e);
  }
}

}  // namespace femb
