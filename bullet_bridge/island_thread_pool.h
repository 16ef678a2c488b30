// A small persistent pool of std::threads for the independent work of a world substep: the
// unconstrained steps of the deformable bodies (docs/architecture.md §3, stage 2) and the solves
// of the deformable islands (stage 6). DeformableWorld::SetThreadCount makes one.
#pragma once

#include <atomic>
#include <chrono>
#include <condition_variable>
#include <exception>
#include <mutex>
#include <thread>
#include <vector>

#include "plugin/element_loop_runner.h"

namespace taut {

// Runs tasks 0..n-1 on num_threads threads, the calling thread one of them. Tasks are taken in
// index order from a shared counter, so which thread runs which task varies from run to run: a
// task must write only its own results (its own island, its own bodies, its own slot of an output
// array) and merges are done by the caller after Run, in task order. Run is not reentrant (a task
// must not call Run) and is called from one thread at a time. Run allocates nothing unless a task
// throws.
//
// Waits spin (yielding) for up to kSpinTime before they block: waking a blocked thread costs
// 0.1-2 ms on a virtual machine (the idle vCPU has to be scheduled again), as much as a whole
// body's unconstrained step, and a world step calls Run twice in quick succession.
// It also splits one body's element loops (ElementLoopRunner) when the bodies are stepped one at
// a time.
class IslandThreadPool : public ElementLoopRunner {
 public:
  static constexpr std::chrono::microseconds kSpinTime{500};

  // Starts num_threads - 1 worker threads; throws InputError unless num_threads >= 1.
  explicit IslandThreadPool(int num_threads);
  // Stops and joins the workers.
  ~IslandThreadPool() override;
  IslandThreadPool(const IslandThreadPool&) = delete;
  IslandThreadPool& operator=(const IslandThreadPool&) = delete;

  // Threads that run tasks, the caller included.
  int num_threads() const { return static_cast<int>(workers_.size()) + 1; }
  int num_loop_threads() const override { return num_threads(); }

  // Calls task(i) once for every i in [0, num_tasks) and returns when every call has returned.
  // Every task runs even when another throws; then the exception of the lowest task index is
  // rethrown (the one a loop over the tasks in order would have met first).
  template <typename Task>
  void Run(int num_tasks, Task& task) {
    RunErased(
        num_tasks, [](void* t, int i) { (*static_cast<Task*>(t))(i); }, &task);
  }

 protected:
  void RunChunksErased(int num_chunks, ChunkCall call, void* chunk) override {
    RunErased(num_chunks, call, chunk);
  }

 private:
  using TaskCall = void (*)(void* task, int index);
  void RunErased(int num_tasks, TaskCall call, void* task);
  // A worker's life: waits for a Run, takes tasks until none is left, reports done.
  void WorkerLoop();
  // Takes and runs tasks of the current Run until every index is taken.
  void RunTasks();

  std::vector<std::thread> workers_;
  std::mutex mutex_;
  std::condition_variable start_;  // a Run began (generation_ changed) or stopping_
  std::condition_variable done_;   // the last busy worker finished its tasks
  // The current Run; written under mutex_ before generation_ changes.
  TaskCall call_ = nullptr;
  void* task_ = nullptr;
  int num_tasks_ = 0;
  std::atomic<int> next_task_{0};
  std::atomic<unsigned long> generation_{0};  // Runs started so far (changed under mutex_)
  std::atomic<int> busy_workers_{0};          // workers still taking tasks of the current Run
  std::atomic<bool> stopping_{false};         // changed under mutex_
  // Lowest failed task of the current Run and its exception (under mutex_).
  int failed_task_ = 0;
  std::exception_ptr failure_;
};

}  // namespace taut
