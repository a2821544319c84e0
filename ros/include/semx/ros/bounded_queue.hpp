// A thread-safe FIFO of bounded length that never blocks the producer: when full, the oldest
// item is dropped and counted. The bridge's LCM thread hands messages to its ROS thread through
// these, so a slow ROS (or a dead master) costs dropped messages, never a stalled semx set.
#pragma once

#include <chrono>
#include <condition_variable>
#include <cstddef>
#include <cstdint>
#include <deque>
#include <mutex>
#include <vector>

namespace semx::rosbridge {

template <class T>
class BoundedQueue {
 public:
  explicit BoundedQueue(std::size_t capacity) : capacity_(capacity == 0 ? 1 : capacity) {}

  // Returns false when an older item was dropped to make room.
  bool push(T item) {
    bool dropped = false;
    {
      std::lock_guard<std::mutex> lock(mutex_);
      if (items_.size() >= capacity_) {
        items_.pop_front();
        ++dropped_;
        dropped = true;
      }
      items_.push_back(std::move(item));
      ++pushed_;
    }
    ready_.notify_one();
    return !dropped;
  }

  // Everything queued, oldest first; waits up to `timeout` for the first item.
  std::vector<T> take_all(std::chrono::milliseconds timeout = std::chrono::milliseconds(0)) {
    std::unique_lock<std::mutex> lock(mutex_);
    if (items_.empty() && timeout.count() > 0) {
      ready_.wait_for(lock, timeout, [this] { return !items_.empty(); });
    }
    std::vector<T> out;
    out.reserve(items_.size());
    for (auto& i : items_) out.push_back(std::move(i));
    items_.clear();
    return out;
  }

  std::size_t size() const {
    std::lock_guard<std::mutex> lock(mutex_);
    return items_.size();
  }
  std::size_t capacity() const { return capacity_; }
  int64_t dropped() const {
    std::lock_guard<std::mutex> lock(mutex_);
    return dropped_;
  }
  int64_t pushed() const {
    std::lock_guard<std::mutex> lock(mutex_);
    return pushed_;
  }

 private:
  const std::size_t capacity_;
  mutable std::mutex mutex_;
  std::condition_variable ready_;
  std::deque<T> items_;
  int64_t dropped_ = 0;
  int64_t pushed_ = 0;
};

}  // namespace semx::rosbridge
