// The single-producer/single-consumer queue: its capacity, FIFO order across the ring's wrap,
// partial and all-or-nothing pushes, peek/drop, and order kept between two threads.
#include "synth/spsc_queue.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <numeric>
#include <thread>
#include <vector>

namespace hamiltone {
namespace {

TEST(SpscQueue, HoldsAtLeastTheRequestedCapacity) {
  for (size_t requested : {1u, 2u, 3u, 7u, 8u, 100u, 1000u, 4096u}) {
    SCOPED_TRACE(requested);
    SpscQueue<int> q(requested);
    EXPECT_GE(q.capacity(), requested);
    std::vector<int> items(q.capacity() + 1);
    EXPECT_EQ(q.push(items.data(), items.size()), q.capacity());  // one too many: dropped
    EXPECT_FALSE(q.push(0));
  }
}

TEST(SpscQueue, KeepsOrderAcrossTheWrap) {
  SpscQueue<int> q(7);  // a ring of 8
  ASSERT_EQ(q.capacity(), 7u);
  int next = 0, expected = 0;
  for (int round = 0; round < 50; ++round) {  // the indices pass the ring's end many times
    const int n = 1 + round % 7;
    for (int i = 0; i < n; ++i) ASSERT_TRUE(q.push(next++));
    std::vector<int> out(8);
    ASSERT_EQ(q.pop(out.data(), out.size()), size_t(n));
    for (int i = 0; i < n; ++i) ASSERT_EQ(out[i], expected++);
  }
  int item;
  EXPECT_EQ(q.pop(&item, 1), 0u);  // empty
}

TEST(SpscQueue, PushTakesWhatFitsAndPushAllAllOrNothing) {
  SpscQueue<int> q(7);
  std::vector<int> items(10);
  std::iota(items.begin(), items.end(), 0);
  EXPECT_EQ(q.push(items.data(), 5), 5u);
  EXPECT_FALSE(q.pushAll(items.data(), 3));  // 2 slots left: nothing is written
  EXPECT_TRUE(q.pushAll(items.data() + 5, 2));
  EXPECT_EQ(q.push(items.data(), 1), 0u);
  std::vector<int> out(10);
  ASSERT_EQ(q.pop(out.data(), out.size()), 7u);
  for (int i = 0; i < 7; ++i) EXPECT_EQ(out[i], i);
  // Across the wrap too: head and tail now sit at 7.
  EXPECT_TRUE(q.pushAll(items.data(), 7));
  ASSERT_EQ(q.pop(out.data(), out.size()), 7u);
  for (int i = 0; i < 7; ++i) EXPECT_EQ(out[i], i);
}

TEST(SpscQueue, PeekShowsTheOldestAndDropTakesIt) {
  SpscQueue<int> q(3);
  EXPECT_EQ(q.peek(), nullptr);
  int next = 0, expected = 0;
  for (int round = 0; round < 20; ++round) {
    while (q.push(next)) ++next;  // fill
    for (int i = 0; i < 2; ++i) {
      const int* p = q.peek();
      ASSERT_NE(p, nullptr);
      EXPECT_EQ(*p, expected);
      EXPECT_EQ(*q.peek(), expected);  // peeking does not take
      q.drop();
      ++expected;
    }
  }
  int out;
  while (q.pop(&out, 1) == 1) EXPECT_EQ(out, expected++);
  EXPECT_EQ(expected, next);
  EXPECT_EQ(q.peek(), nullptr);
}

// One producer, one consumer, a small ring so that both wait on each other often: every item
// arrives once, in order. The consumer takes by pop and by peek/drop, as the audio thread does.
TEST(SpscQueue, TwoThreadsKeepEveryItemInOrder) {
  constexpr long kItems = 1'000'000;
  SpscQueue<long> q(63);
  std::thread producer([&] {
    long chunk[13];
    for (long next = 0; next < kItems;) {
      const long n = std::min<long>(13, kItems - next);
      std::iota(chunk, chunk + n, next);
      next += static_cast<long>(q.push(chunk, static_cast<size_t>(n)));
    }
  });
  long expected = 0, outOfOrder = 0;
  long chunk[17];
  while (expected < kItems) {
    if (expected % 2) {
      const size_t n = q.pop(chunk, 17);
      for (size_t i = 0; i < n; ++i) outOfOrder += chunk[i] != expected++;
    } else if (const long* p = q.peek()) {
      outOfOrder += *p != expected++;
      q.drop();
    }
  }
  producer.join();
  EXPECT_EQ(outOfOrder, 0);
  EXPECT_EQ(q.peek(), nullptr);
}

}  // namespace
}  // namespace hamiltone
