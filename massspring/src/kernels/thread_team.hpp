#pragma once

// A persistent team of threads for the fast stepper (internal). The caller is member 0; run(job)
// executes job(member) on every member and returns when all are done. Inside a job, barrier()
// synchronises the members by spinning (steps last tens of microseconds; sleeping would cost more
// than the work), yielding after a while so that an oversubscribed machine still makes progress.

#include <atomic>
#include <condition_variable>
#include <functional>
#include <mutex>
#include <thread>
#include <vector>

namespace msfem::massspring::detail {

class ThreadTeam {
 public:
  explicit ThreadTeam(int size);
  ~ThreadTeam();
  ThreadTeam(const ThreadTeam&) = delete;
  ThreadTeam& operator=(const ThreadTeam&) = delete;

  int size() const { return size_; }
  void run(const std::function<void(int)>& job);
  void barrier();

 private:
  void worker(int member);

  int size_;
  std::vector<std::thread> workers_;
  std::mutex mutex_;
  std::condition_variable wake_;
  const std::function<void(int)>* job_ = nullptr;
  long job_generation_ = 0;
  bool stopping_ = false;
  std::atomic<int> finished_{0};
  std::atomic<int> arrived_{0};
  std::atomic<long> barrier_generation_{0};
};

}  // namespace msfem::massspring::detail
