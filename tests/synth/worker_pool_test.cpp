// The worker pool: every job of every list runs exactly once and has returned when run() does,
// whatever the threads and however the lists' lengths compare with them; jobs on the workers run
// with flush-to-zero on, with every signal blocked and with the scheduling they were given.
#include "synth/worker_pool.h"

#include <gtest/gtest.h>
#include <pthread.h>
#include <signal.h>

#include <atomic>
#include <thread>
#include <vector>

#include "synth/denormals.h"

namespace hamiltone {
namespace {

// 2000 lists of lengths 0 … 9 and a long one now and then: most lists end while woken workers
// are still on their way, so stale wake-ups meet new lists.
TEST(WorkerPool, RunsEveryJobOnceAndReturnsAfterAllHaveReturned) {
  for (int threads : {1, 2, 3, 5}) {
    WorkerPool pool(threads);
    EXPECT_EQ(pool.threads(), threads);
    std::vector<std::atomic<int>> runs(200);
    for (int list = 0; list < 2000; ++list) {
      const int count = list % 50 == 0 ? 200 : list % 10;
      for (int i = 0; i < count; ++i) runs[i].store(0, std::memory_order_relaxed);
      auto job = [&](int i) noexcept {
        volatile double x = 0.0;  // a little work, so that claims interleave
        for (int k = 0; k < 100 * (i % 7); ++k) x = x + 1.0;
        runs[i].fetch_add(1, std::memory_order_relaxed);
      };
      pool.run(count, job);
      for (int i = 0; i < count; ++i)
        ASSERT_EQ(runs[i].load(std::memory_order_relaxed), 1)
            << threads << " threads, list " << list << " of " << count << ", job " << i;
    }
  }
}

// The synthesizer calls run() with flush-to-zero on; the workers have it on too, so a voice's
// samples do not depend on the thread that rendered it.
TEST(WorkerPool, JobsRunWithFlushToZeroOnEveryThread) {
  WorkerPool pool(3);
  const ScopedFlushToZero ftz;
  std::atomic<int> without{0};
  auto job = [&](int) noexcept {
    if (!ScopedFlushToZero::active()) without.fetch_add(1);
    volatile double x = 0.0;
    for (int k = 0; k < 20000; ++k) x = x + 1.0;  // long enough for the workers to take some
  };
  for (int list = 0; list < 50; ++list) pool.run(16, job);
  EXPECT_EQ(without.load(), 0);
}

TEST(WorkerPool, WorkersBlockEverySignalAndTheCallerKeepsItsMask) {
  sigset_t before, after;
  pthread_sigmask(SIG_SETMASK, nullptr, &before);
  WorkerPool pool(3);
  pthread_sigmask(SIG_SETMASK, nullptr, &after);
  for (int s = 1; s < SIGRTMIN; ++s)
    EXPECT_EQ(sigismember(&before, s), sigismember(&after, s)) << s;
  const std::thread::id caller = std::this_thread::get_id();
  std::atomic<int> unblocked{0};
  auto job = [&](int) noexcept {
    if (std::this_thread::get_id() == caller) return;
    sigset_t mask;
    pthread_sigmask(SIG_SETMASK, nullptr, &mask);
    for (int s : {SIGINT, SIGTERM, SIGHUP, SIGPIPE, SIGUSR1, SIGALRM})
      if (!sigismember(&mask, s)) unblocked.fetch_add(1);
  };
  for (int list = 0; list < 50; ++list) pool.run(16, job);
  EXPECT_EQ(unblocked.load(), 0);
}

// SCHED_BATCH rather than a real-time policy: a test must not take real-time priority.
TEST(WorkerPool, WorkersTakeTheSchedulingAsked) {
  WorkerPool pool(3);
  EXPECT_TRUE(pool.schedule(SCHED_BATCH, 0));
  EXPECT_FALSE(pool.schedule(SCHED_FIFO, 1000));  // beyond any priority: refused
  const std::thread::id caller = std::this_thread::get_id();
  std::atomic<int> other{0};
  auto job = [&](int) noexcept {
    if (std::this_thread::get_id() == caller) return;
    int policy = -1;
    sched_param param{};
    if (pthread_getschedparam(pthread_self(), &policy, &param) != 0 || policy != SCHED_BATCH)
      other.fetch_add(1);
  };
  for (int list = 0; list < 50; ++list) pool.run(16, job);
  EXPECT_EQ(other.load(), 0);
}

TEST(WorkerPool, RefusesFewerThanOneThread) { EXPECT_THROW(WorkerPool(0), std::invalid_argument); }

}  // namespace
}  // namespace hamiltone
