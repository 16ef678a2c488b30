#include "bullet_bridge/island_thread_pool.h"

#include "plugin/common.h"

namespace taut {

namespace {
// Yields until done() or kSpinTime has passed; true when done() became true.
template <typename Done>
bool SpinUntil(const Done& done) {
  const auto end = std::chrono::steady_clock::now() + IslandThreadPool::kSpinTime;
  for (int i = 0;; ++i) {
    if (done()) return true;
    if (i % 16 == 15 && std::chrono::steady_clock::now() > end) return false;
    std::this_thread::yield();
  }
}
}  // namespace

IslandThreadPool::IslandThreadPool(int num_threads) {
  TAUT_DEMAND(num_threads >= 1, "IslandThreadPool: thread count must be >= 1, got ", num_threads);
  workers_.reserve(num_threads - 1);
  for (int t = 1; t < num_threads; ++t) workers_.emplace_back([this] { WorkerLoop(); });
}

IslandThreadPool::~IslandThreadPool() {
  {
    std::lock_guard<std::mutex> lock(mutex_);
    stopping_ = true;
  }
  start_.notify_all();
  for (std::thread& worker : workers_) worker.join();
}

void IslandThreadPool::RunErased(int num_tasks, TaskCall call, void* task) {
  if (num_tasks <= 0) return;
  {
    std::lock_guard<std::mutex> lock(mutex_);
    call_ = call;
    task_ = task;
    num_tasks_ = num_tasks;
    next_task_.store(0, std::memory_order_relaxed);
    failed_task_ = num_tasks;
    failure_ = nullptr;
    busy_workers_.store(static_cast<int>(workers_.size()), std::memory_order_relaxed);
    // Release: a worker that sees the new generation (spinning or woken) sees the job above.
    generation_.fetch_add(1, std::memory_order_release);
  }
  start_.notify_all();
  RunTasks();
  // Acquire: each worker's task results happen before its decrement.
  auto workers_done = [this] { return busy_workers_.load(std::memory_order_acquire) == 0; };
  std::exception_ptr failure;
  if (!SpinUntil(workers_done)) {
    std::unique_lock<std::mutex> lock(mutex_);
    done_.wait(lock, workers_done);
  }
  {
    std::lock_guard<std::mutex> lock(mutex_);
    failure = std::move(failure_);
    failure_ = nullptr;
  }
  if (failure) std::rethrow_exception(failure);
}

void IslandThreadPool::WorkerLoop() {
  unsigned long seen = 0;
  auto started = [&] {
    return stopping_.load(std::memory_order_relaxed) ||
           generation_.load(std::memory_order_acquire) != seen;
  };
  for (;;) {
    if (!SpinUntil(started)) {
      std::unique_lock<std::mutex> lock(mutex_);
      start_.wait(lock, started);
    }
    if (stopping_.load(std::memory_order_relaxed)) return;
    seen = generation_.load(std::memory_order_acquire);
    RunTasks();
    // The last worker out wakes the caller should it have stopped spinning; the notify is under
    // the mutex so that it cannot fall between the caller's check and its wait.
    if (busy_workers_.fetch_sub(1, std::memory_order_acq_rel) == 1) {
      std::lock_guard<std::mutex> lock(mutex_);
      done_.notify_one();
    }
  }
}

void IslandThreadPool::RunTasks() {
  for (;;) {
    const int i = next_task_.fetch_add(1, std::memory_order_relaxed);
    if (i >= num_tasks_) return;
    try {
      call_(task_, i);
    } catch (...) {
      std::lock_guard<std::mutex> lock(mutex_);
      if (i < failed_task_) {
        failed_task_ = i;
        failure_ = std::current_exception();
      }
    }
  }
}

}  // namespace taut
