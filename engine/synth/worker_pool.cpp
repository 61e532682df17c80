// The pool's threads, the publication of a list and the claim of its jobs.
#include "synth/worker_pool.h"

#include <pthread.h>
#include <signal.h>

#include <algorithm>
#include <stdexcept>
#include <string>

#include "synth/denormals.h"

namespace hamiltone {

WorkerPool::WorkerPool(int threads) {
  if (threads < 1)
    throw std::invalid_argument("threads = " + std::to_string(threads) + ": at least 1");
  workers_.reserve(static_cast<size_t>(threads - 1));
  // The workers block every signal, so a signal sent to the program reaches the threads it had
  // before (hamiltone-render holds signals back on its thread while it commits its file;
  // hamiltone-play takes them with sigtimedwait). A thread inherits its creator's mask.
  sigset_t all, saved;
  sigfillset(&all);
  pthread_sigmask(SIG_SETMASK, &all, &saved);
  try {
    for (int i = 1; i < threads; ++i) {
      workers_.push_back(std::make_unique<Worker>());
      Worker& worker = *workers_.back();
      sem_init(&worker.wake, 0, 0);
      worker.thread = std::thread([this, &worker] { work(worker); });
    }
  } catch (...) {
    pthread_sigmask(SIG_SETMASK, &saved, nullptr);
    stop();
    throw;
  }
  pthread_sigmask(SIG_SETMASK, &saved, nullptr);
}

WorkerPool::~WorkerPool() { stop(); }

void WorkerPool::stop() noexcept {
  stopping_.store(true, std::memory_order_release);
  for (auto& worker : workers_) sem_post(&worker->wake);
  for (auto& worker : workers_) {
    if (worker->thread.joinable()) worker->thread.join();
    sem_destroy(&worker->wake);
  }
  workers_.clear();
}

bool WorkerPool::schedule(int policy, int priority) noexcept {
  sched_param param{};
  param.sched_priority = priority;
  bool all = true;
  for (auto& worker : workers_)
    all = pthread_setschedparam(worker->thread.native_handle(), policy, &param) == 0 && all;
  return all;
}

void WorkerPool::work(Worker& worker) noexcept {
  const ScopedFlushToZero ftz;  // as Synth::process has it on the calling thread
  for (;;) {
    while (sem_wait(&worker.wake) != 0) {  // EINTR only: the semaphore is valid
    }
    if (stopping_.load(std::memory_order_acquire)) return;
    drain();
  }
}

void WorkerPool::run(int count, Call call, void* job) noexcept {
  if (workers_.empty() || count < 2) {  // nothing to share
    for (int i = 0; i < count; ++i) call(job, i);
    return;
  }
  // No worker holds a claim on the last list (its jobs are done), so the list can be rewritten.
  call_ = call;
  job_ = job;
  done_.store(0, std::memory_order_relaxed);
  ticket_.store(static_cast<std::uint64_t>(count) << 32, std::memory_order_release);
  // sem_post, not std::atomic::notify_all or std::counting_semaphore::release: libstdc++ wakes
  // those through syscall(SYS_futex), which RealtimeSanitizer reports in a real-time context.
  // glibc's sem_post makes the same futex wake, only when the worker sleeps (else it is one atomic
  // add), and the sanitizer accepts it. No more workers are woken than there are jobs to share.
  const int wake = std::min(static_cast<int>(workers_.size()), count - 1);
  for (int w = 0; w < wake; ++w) sem_post(&workers_[w]->wake);
  drain();
  while (done_.load(std::memory_order_acquire) < count) spinPause();
}

void WorkerPool::drain() noexcept {
  for (;;) {
    const std::uint64_t ticket = ticket_.fetch_add(1, std::memory_order_acq_rel);
    const auto item = static_cast<std::uint32_t>(ticket);
    if (item >= static_cast<std::uint32_t>(ticket >> 32)) return;  // all claimed, or a stale list
    call_(job_, static_cast<int>(item));
    done_.fetch_add(1, std::memory_order_release);
  }
}

}  // namespace hamiltone
