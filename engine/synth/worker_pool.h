// A fixed set of worker threads that help the calling (audio) thread through a list of jobs: the
// threads start with the pool, before any stream, and sleep between lists. The caller publishes a
// list, wakes the workers and claims jobs itself from a shared atomic index, so a job no worker
// has claimed yet is the caller's; it never waits on a lock or a condition variable: once every
// job is claimed, it spins (with a pause instruction) until those the workers took are done.
#pragma once

#include <semaphore.h>

#include <atomic>
#include <cstdint>
#include <memory>
#include <thread>
#include <vector>

#include "synth/nonblocking.h"

#if defined(__x86_64__) || defined(__i386__)
#include <immintrin.h>
#endif

namespace hamiltone {

// Tells the core this thread is spinning: less power, and the other hyperthread runs on.
inline void spinPause() noexcept {
#if defined(__x86_64__) || defined(__i386__)
  _mm_pause();
#elif defined(__aarch64__)
  asm volatile("yield");
#endif
}

class WorkerPool {
 public:
  // `threads` in all, the caller's included: threads − 1 workers (1: none, run() is a plain loop).
  // Throws std::invalid_argument below 1, std::system_error when a thread cannot start.
  explicit WorkerPool(int threads);
  ~WorkerPool();  // wakes, stops and joins the workers
  WorkerPool(const WorkerPool&) = delete;
  WorkerPool& operator=(const WorkerPool&) = delete;

  int threads() const { return static_cast<int>(workers_.size()) + 1; }

  // Gives every worker this scheduling policy and priority (pthread_setschedparam): a caller with
  // real-time priority should share it with the workers, or it may spin on a job that a worker
  // of lower priority holds while other threads run. False when the system refuses (no rights).
  bool schedule(int policy, int priority) noexcept;

  // Calls job(i) once for each i in [0, count), on this thread and the workers, and returns once
  // every call has returned. The jobs are claimed in the order of i (each thread claims the next
  // and runs it before it claims another), so a job may wait for one before it: that one is held
  // by a thread that does not wait for it, and will run (a spinning wait then needs that thread
  // to have a core: no more threads than cores).
  // Jobs run with flush-to-zero on (denormals.h) on every thread, as the synthesizer runs its
  // voices: a job's result must not depend on the thread it ran on. Real-time safe on this thread:
  // no allocation, lock or blocking call; only a wake-up posted to each sleeping worker. One caller
  // at a time.
  template <class Job>
  void run(int count, Job& job) noexcept {
    run(
        count, [](void* j, int item) noexcept { (*static_cast<Job*>(j))(item); }, &job);
  }

 private:
  using Call = void (*)(void* job, int item) noexcept;
  struct Worker {
    sem_t wake;  // posted once per list
    std::thread thread;
  };

  void run(int count, Call call, void* job) noexcept;
  // Claims and runs jobs until none is left; in RealtimeSanitizer's real-time context on the
  // workers too, so the jobs are checked there as on the audio thread.
  void drain() noexcept HAMILTONE_NONBLOCKING;
  void work(Worker& worker) noexcept;
  void stop() noexcept;

  std::vector<std::unique_ptr<Worker>> workers_;  // fixed addresses: the semaphores must not move
  Call call_ = nullptr;                           // the list: written before ticket_ publishes it
  void* job_ = nullptr;
  // count << 32 | the next job to claim. Count and index in one word, so a worker's claim can
  // never pair a stale list's index with a new list's count.
  alignas(64) std::atomic<std::uint64_t> ticket_{0};
  alignas(64) std::atomic<int> done_{0};  // jobs of the list that returned
  std::atomic<bool> stopping_{false};
};

}  // namespace hamiltone
