// Flush-to-zero and denormals-are-zero for the thread that runs the engine, for one scope: a
// decaying voice would otherwise spend its tail in subnormal arithmetic, tens of times slower.
#pragma once

#if defined(__SSE__) || defined(__x86_64__)
#include <xmmintrin.h>
#endif

namespace hamiltone {

class ScopedFlushToZero {
 public:
#if defined(__SSE__) || defined(__x86_64__)
  static constexpr unsigned kBits = 0x8040;  // MXCSR: FTZ (bit 15) and DAZ (bit 6)
  ScopedFlushToZero() noexcept : saved_(_mm_getcsr()) { _mm_setcsr(saved_ | kBits); }
  ~ScopedFlushToZero() { _mm_setcsr(saved_); }
  static bool active() noexcept { return (_mm_getcsr() & kBits) == kBits; }

 private:
  unsigned saved_;
#elif defined(__aarch64__)
  static constexpr unsigned long kBits = 1ul << 24;  // FPCR.FZ
  ScopedFlushToZero() noexcept {
    asm volatile("mrs %0, fpcr" : "=r"(saved_));
    asm volatile("msr fpcr, %0" ::"r"(saved_ | kBits));
  }
  ~ScopedFlushToZero() { asm volatile("msr fpcr, %0" ::"r"(saved_)); }
  static bool active() noexcept {
    unsigned long fpcr;
    asm volatile("mrs %0, fpcr" : "=r"(fpcr));
    return (fpcr & kBits) != 0;
  }

 private:
  unsigned long saved_;
#else
  static bool active() noexcept { return false; }  // no known control register: a no-op
#endif
 public:
  ScopedFlushToZero(const ScopedFlushToZero&) = delete;
  ScopedFlushToZero& operator=(const ScopedFlushToZero&) = delete;
};

}  // namespace hamiltone
