#pragma once
// A bounded multi-producer/multi-consumer queue between the daemon's stages. What happens when
// it is full is the station's choice: drop the oldest item (the caller counts it as a missed
// part) or make the producer wait (back-pressure up to the trigger).

#include <chrono>
#include <condition_variable>
#include <cstddef>
#include <deque>
#include <mutex>
#include <optional>

namespace facet::service {

enum class OverflowPolicy { DropOldest, Block };

template <class T>
class BoundedQueue {
 public:
  BoundedQueue(std::size_t capacity, OverflowPolicy policy)
      : capacity_(capacity), policy_(policy) {}

  // Adds an item. With DropOldest a full queue gives up its oldest item, which is returned so
  // that the caller can account for it; with Block the call waits for room (or close()).
  // Returns the dropped item, if any. After close() the item is returned unqueued.
  std::optional<T> push(T item) {
    std::unique_lock lock(mutex_);
    if (policy_ == OverflowPolicy::Block)
      notFull_.wait(lock, [&] { return closed_ || items_.size() < capacity_; });
    if (closed_) return item;
    std::optional<T> dropped;
    if (items_.size() >= capacity_) {
      dropped = std::move(items_.front());
      items_.pop_front();
    }
    items_.push_back(std::move(item));
    notEmpty_.notify_one();
    return dropped;
  }

  // Waits up to `timeout` for an item; empty when the time ran out or the queue is closed and
  // empty.
  std::optional<T> pop(std::chrono::milliseconds timeout) {
    std::unique_lock lock(mutex_);
    if (!notEmpty_.wait_for(lock, timeout, [&] { return closed_ || !items_.empty(); }))
      return std::nullopt;
    if (items_.empty()) return std::nullopt;
    T item = std::move(items_.front());
    items_.pop_front();
    notFull_.notify_one();
    return item;
  }

  // Wakes every waiter; pushes are refused from now on, pops drain what is left.
  void close() {
    std::lock_guard lock(mutex_);
    closed_ = true;
    notEmpty_.notify_all();
    notFull_.notify_all();
  }

  [[nodiscard]] std::size_t size() const {
    std::lock_guard lock(mutex_);
    return items_.size();
  }
  [[nodiscard]] bool closed() const {
    std::lock_guard lock(mutex_);
    return closed_;
  }
  [[nodiscard]] std::size_t capacity() const { return capacity_; }

 private:
  const std::size_t capacity_;
  const OverflowPolicy policy_;
  mutable std::mutex mutex_;
  std::condition_variable notEmpty_, notFull_;
  std::deque<T> items_;
  bool closed_ = false;
};

}  // namespace facet::service
