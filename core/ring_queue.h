// A FIFO on a ring buffer that keeps its storage: push_back allocates only when the queue outgrows
// its capacity (which then doubles and never shrinks), so a queue whose length is bounded stops
// allocating once it reached its largest length. For the per-step queues of the closed loop (CAN
// bus queues, delay lines), where std::deque allocates and frees a block every few elements.
#pragma once
#include <cstddef>
#include <utility>
#include <vector>

namespace exotwin {

template <class T>
class RingQueue {
 public:
  bool empty() const { return size_ == 0; }
  size_t size() const { return size_; }
  // Element i (0 = front); precondition i < size().
  T& operator[](size_t i) { return slots_[Wrap(head_ + i)]; }
  const T& operator[](size_t i) const { return slots_[Wrap(head_ + i)]; }
  // Preconditions: !empty().
  T& front() { return slots_[head_]; }
  const T& front() const { return slots_[head_]; }
  T& back() { return (*this)[size_ - 1]; }
  const T& back() const { return (*this)[size_ - 1]; }
  void push_back(T v) {
    if (size_ == slots_.size()) Grow();
    slots_[Wrap(head_ + size_)] = std::move(v);
    ++size_;
  }
  void pop_front() {
    head_ = Wrap(head_ + 1);
    --size_;
  }
  // Empties the queue, keeping the storage.
  void clear() { head_ = size_ = 0; }

 private:
  size_t Wrap(size_t i) const { return i >= slots_.size() ? i - slots_.size() : i; }
  void Grow() {
    std::vector<T> bigger(slots_.empty() ? 16 : 2 * slots_.size());
    for (size_t i = 0; i < size_; ++i) bigger[i] = std::move((*this)[i]);
    slots_ = std::move(bigger);
    head_ = 0;
  }

  std::vector<T> slots_;
  size_t head_ = 0, size_ = 0;
};

}  // namespace exotwin
