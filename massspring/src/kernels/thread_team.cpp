#include "thread_team.hpp"

namespace msfem::massspring::detail {
namespace {

inline void spin_pause(int& spins) {
  if (++spins > 256) {
    std::this_thread::yield();
  } else {
#if defined(__x86_64__) || defined(__i386__)
    __builtin_ia32_pause();
#endif
  }
}

}  // namespace

ThreadTeam::ThreadTeam(int size) : size_(size < 1 ? 1 : size) {
  for (int member = 1; member < size_; ++member)
    workers_.emplace_back([this, member] { worker(member); });
}

ThreadTeam::~ThreadTeam() {
  {
    std::lock_guard<std::mutex> lock(mutex_);
    stopping_ = true;
  }
  wake_.notify_all();
  for (auto& thread : workers_)
    thread.join();
}

void ThreadTeam::worker(int member) {
  long seen = 0;
  while (true) {
    const std::function<void(int)>* job = nullptr;
    {
      std::unique_lock<std::mutex> lock(mutex_);
      wake_.wait(lock, [&] { return stopping_ || job_generation_ != seen; });
      if (stopping_) return;
      seen = job_generation_;
      job = job_;
    }
    (*job)(member);
    finished_.fetch_add(1, std::memory_order_acq_rel);
  }
}

void ThreadTeam::run(const std::function<void(int)>& job) {
  if (size_ == 1) {
    job(0);
    return;
  }
  finished_.store(0, std::memory_order_relaxed);
  {
    std::lock_guard<std::mutex> lock(mutex_);
    job_ = &job;
    ++job_generation_;
  }
  wake_.notify_all();
  job(0);
  int spins = 0;
  while (finished_.load(std::memory_order_acquire) != size_ - 1)
    spin_pause(spins);
}

void ThreadTeam::barrier() {
  if (size_ == 1) return;
  const long generation = barrier_generation_.load(std::memory_order_acquire);
  if (arrived_.fetch_add(1, std::memory_order_acq_rel) == size_ - 1) {
    arrived_.store(0, std::memory_order_relaxed);
    barrier_generation_.fetch_add(1, std::memory_order_acq_rel);
    return;
  }
  int spins = 0;
  while (barrier_generation_.load(std::memory_order_acquire) == generation)
    spin_pause(spins);
}

}  // namespace msfem::massspring::detail
