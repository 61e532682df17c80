// A bounded single-producer/single-consumer queue, lock-free and wait-free: one thread pushes,
// another pops, neither ever blocks or allocates after construction. For MIDI messages into the
// audio thread and for recorded samples out of it.
#pragma once

#include <algorithm>
#include <atomic>
#include <cstddef>
#include <new>
#include <type_traits>
#include <vector>

namespace hamiltone {

template <class T>
class SpscQueue {
  static_assert(std::is_trivially_copyable_v<T>);

 public:
  // Holds at least `capacity` items: the ring is a power of two (indices wrap with a mask) with
  // one slot kept empty.
  explicit SpscQueue(size_t capacity) {
    size_t size = 2;
    while (size < capacity + 1) size *= 2;
    items_.resize(size);
    mask_ = size - 1;
  }

  // Producer: appends up to `count` items; returns how many fit (the rest are dropped).
  size_t push(const T* items, size_t count) noexcept {
    const size_t tail = tail_.load(std::memory_order_relaxed);
    const size_t head = head_.load(std::memory_order_acquire);
    const size_t n = std::min(count, mask_ - (tail - head));
    for (size_t i = 0; i < n; ++i) items_[(tail + i) & mask_] = items[i];
    tail_.store(tail + n, std::memory_order_release);
    return n;
  }
  bool push(const T& item) noexcept { return push(&item, 1) == 1; }
  // Producer: appends all `count` items, or none if they do not all fit.
  bool pushAll(const T* items, size_t count) noexcept {
    const size_t used =
        tail_.load(std::memory_order_relaxed) - head_.load(std::memory_order_acquire);
    return count <= mask_ - used && push(items, count) == count;
  }

  // Consumer: takes up to `count` items; returns how many it took.
  size_t pop(T* items, size_t count) noexcept {
    const size_t head = head_.load(std::memory_order_relaxed);
    const size_t tail = tail_.load(std::memory_order_acquire);
    const size_t n = std::min(count, tail - head);
    for (size_t i = 0; i < n; ++i) items[i] = items_[(head + i) & mask_];
    head_.store(head + n, std::memory_order_release);
    return n;
  }
  // Consumer: the oldest item without taking it, or nullptr.
  const T* peek() const noexcept {
    const size_t head = head_.load(std::memory_order_relaxed);
    return head == tail_.load(std::memory_order_acquire) ? nullptr : &items_[head & mask_];
  }
  void drop() noexcept {
    head_.store(head_.load(std::memory_order_relaxed) + 1, std::memory_order_release);
  }

  size_t capacity() const { return mask_; }

 private:
  std::vector<T> items_;
  size_t mask_ = 0;
  // Free-running counters (their difference is the fill), each on its own cache line.
  alignas(64) std::atomic<size_t> head_{0};
  alignas(64) std::atomic<size_t> tail_{0};
};

}  // namespace hamiltone
