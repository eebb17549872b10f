#pragma once
// A fixed set of threads that run `job(index, worker)` for every index of [0, count), each index once, indices
// handed out in order to whichever thread is free (as OpenMP's schedule(dynamic, 1)). The calling thread is worker
// 0, the pool's own threads are workers 1 ... threads - 1; run() returns when every index is done.
//
// Why not `#pragma omp parallel for`: libgomp's threads spin at the end of every parallel region (OMP_WAIT_POLICY
// and GOMP_SPINCOUNT are read once, when the library loads, before the host could set them), and on a machine
// where another process keeps a core busy the spinning thread takes CPU time from the one still working. Measured
// with bench/performance.cpp figure 3b: 2 threads took about twice as long as 1 on a loaded machine with libgomp's
// default, 1.75x faster with OMP_WAIT_POLICY=passive. These threads sleep on a condition variable instead.
//
// `job` must not throw (the driver keeps each block's exception in the block). Not reentrant: one run() at a time.
#include <atomic>
#include <condition_variable>
#include <cstddef>
#include <cstdint>
#include <functional>
#include <mutex>
#include <thread>
#include <vector>

namespace nonsep::host {

class WorkerPool {
 public:
  using Job = std::function<void(std::size_t index, std::size_t worker)>;

  explicit WorkerPool(std::size_t threads) {
    for (std::size_t worker = 1; worker < threads; ++worker) threads_.emplace_back([this, worker] { serve(worker); });
  }
  ~WorkerPool() {
    {
      const std::lock_guard lock(mutex_);
      stop_ = true;
    }
    start_.notify_all();
    for (auto& thread : threads_) thread.join();
  }
  WorkerPool(const WorkerPool&) = delete;
  WorkerPool& operator=(const WorkerPool&) = delete;

  void run(std::size_t count, const Job& job) {
    if (threads_.empty()) {
      for (std::size_t index = 0; index < count; ++index) job(index, 0);
      return;
    }
    {
      const std::lock_guard lock(mutex_);
      job_ = &job;
      count_ = count;
      next_.store(0);
      busy_ = threads_.size();
      ++generation_;
    }
    start_.notify_all();
    work(job, count, 0);
    std::unique_lock lock(mutex_);
    done_.wait(lock, [this] { return busy_ == 0; });
    job_ = nullptr;
  }

 private:
  void work(const Job& job, std::size_t count, std::size_t worker) {
    for (std::size_t index = next_.fetch_add(1); index < count; index = next_.fetch_add(1)) job(index, worker);
  }

  void serve(std::size_t worker) {
    std::uint64_t seen = 0;
    for (;;) {
      std::unique_lock lock(mutex_);
      start_.wait(lock, [&] { return stop_ || generation_ != seen; });
      if (stop_) return;
      seen = generation_;
      const Job& job = *job_;
      const std::size_t count = count_;
      lock.unlock();
      work(job, count, worker);
      lock.lock();
      if (--busy_ == 0) done_.notify_one();
    }
  }

  std::mutex mutex_;
  std::condition_variable start_, done_;
  const Job* job_ = nullptr;
  std::size_t count_ = 0, busy_ = 0;
  std::uint64_t generation_ = 0;
  bool stop_ = false;
  std::atomic<std::size_t> next_{0};
  std::vector<std::thread> threads_;  // last: started after every member above is initialized
};

}  // namespace nonsep::host
