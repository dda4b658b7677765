#include <thread>

#include <gtest/gtest.h>

#include "service/daemon/bounded_queue.hpp"

namespace facet::service {
namespace {

using namespace std::chrono_literals;

TEST(BoundedQueue, DropOldestHandsBackTheDroppedItem) {
  BoundedQueue<int> q(2, OverflowPolicy::DropOldest);
  EXPECT_FALSE(q.push(1));
  EXPECT_FALSE(q.push(2));
  EXPECT_EQ(q.push(3), 1);
  EXPECT_EQ(q.pop(0ms), 2);
  EXPECT_EQ(q.pop(0ms), 3);
  EXPECT_FALSE(q.pop(1ms));
}

TEST(BoundedQueue, BlockWaitsForRoom) {
  BoundedQueue<int> q(1, OverflowPolicy::Block);
  q.push(1);
  std::atomic<bool> pushed = false;
  std::thread producer([&] {
    q.push(2);
    pushed = true;
  });
  std::this_thread::sleep_for(50ms);
  EXPECT_FALSE(pushed);
  EXPECT_EQ(q.pop(100ms), 1);
  producer.join();
  EXPECT_TRUE(pushed);
  EXPECT_EQ(q.pop(100ms), 2);
}

TEST(BoundedQueue, CloseWakesWaitersAndDrains) {
  BoundedQueue<int> q(4, OverflowPolicy::Block);
  q.push(5);
  q.close();
  EXPECT_EQ(q.push(6), 6);  // refused, handed back
  EXPECT_EQ(q.pop(0ms), 5);
  EXPECT_FALSE(q.pop(10ms));
}

}  // namespace
}  // namespace facet::service
