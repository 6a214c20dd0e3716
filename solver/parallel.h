// Bodies in parallel. A body's forces and matrices depend on its own
// configuration only, so the solver evaluates them on several threads into per-body slots and
// adds the slots into the system in body order: the same bits for any number of threads.
//
// Why not an OpenMP loop: its parallel region ends in a barrier that waits for every thread of
// the team, including one the operating system has not scheduled yet. With two solver runs on
// two cores (ctest -j2, a parameter study) that wait is a time slice per region, three regions
// per step: measured 26x slower than one thread each. Here the calling thread claims bodies (from
// its own range's counter, then the others': BodyThreads::Range) as soon as a pass starts, helpers
// join when they get a core, and the call waits only for bodies a helper has already begun: a
// helper that never runs costs nothing.
#pragma once

#include <atomic>
#include <condition_variable>
#include <exception>
#include <functional>
#include <memory>
#include <mutex>
#include <thread>
#include <vector>

namespace femb {

/// The processors this process may run on (its CPU affinity), at least 1.
int DefaultThreads();

/// A callable f(i) passed by reference, without a copy: what ForEach runs. Unlike a
/// std::function it never allocates (a lambda capturing more than two references would), so a
/// pass allocates nothing. The callable must outlive the pass.
class BodyTask {
 public:
  template <class F>
  BodyTask(const F& f)  // NOLINT: implicit, from any lambda
      : object_(&f), call_([](const void* o, int i) { (*static_cast<const F*>(o))(i); }) {}
  void operator()(int i) const { call_(object_, i); }

 private:
  const void* object_;
  void (*call_)(const void*, int);
};

/// A pool of threads - 1 helper threads that run the bodies of a pass with the calling thread.
class BodyThreads {
 public:
  explicit BodyThreads(int threads = 1);
  ~BodyThreads();
  BodyThreads(const BodyThreads&) = delete;
  BodyThreads& operator=(const BodyThreads&) = delete;

  int threads() const { return int(helpers_.size()) + 1; }

  /// Calls f(i) for i in [0, n), each once, on the calling thread and the helpers. f must write
  /// only to slot i of its outputs. An exception thrown by f(i) is rethrown after the pass (the
  /// one of the lowest i, as a serial loop would).
  void ForEach(int n, BodyTask f);

 private:
  // The bodies of a pass are cut into one contiguous range per thread, each with its own counter:
  // a thread takes the bodies of its range first, then helps with the others' (a helper that
  // joins late finds its range taken). So a body is evaluated on the same core pass after pass
  // and its workspace stays in that core's cache; with one shared counter the bodies changed
  // threads at random and a pass on 2 threads took 0.72 of its time on 1 instead of 0.5.
  struct alignas(64) Range {
    std::atomic<int> next{0};
    int end = 0;
  };
  struct Pass {
    const BodyTask* f = nullptr;
    int n = 0;
    Range* ranges = nullptr;  ///< threads() of them; the pool's, kept between passes
    int n_ranges = 0;
    std::atomic<int> done{0}, users{0};
    std::vector<std::exception_ptr>* errors = nullptr;  ///< per i; the pool's, kept between passes
  };
  static void Work(Pass& pass, int thread);
  void Helper(int thread);

  std::vector<std::thread> helpers_;
  std::mutex mutex_;
  std::condition_variable wake_;
  Pass* pass_ = nullptr;            ///< the pass in progress (under mutex_), nullptr between passes
  long generation_ = 0;             ///< counts passes (under mutex_)
  std::atomic<long> published_{0};  ///< generation_, for helpers looking without the lock
  bool stop_ = false;
  std::vector<std::exception_ptr> errors_;  ///< a pass's (Pass::errors): its storage is reused
  std::unique_ptr<Range[]> ranges_;         ///< a pass's (Pass::ranges), one per thread
};

}  // namespace femb
