#pragma once
// Private to geometry/src: a task run on a second thread beside the caller's own work, joined
// before its result is read (join()) or when the scope ends (also on an exception). Its exception
// is rethrown by join().
#include <exception>
#include <functional>
#include <thread>
#include <utility>

namespace impactdeck::geometry::detail {

class SideTask {
 public:
  /// Runs `task` on a new thread when `parallel`, else at once on this one.
  SideTask(bool parallel, std::function<void()> task) {
    if (!parallel) {
      task();
      return;
    }
    thread_ = std::thread([this, t = std::move(task)] {
      try {
        t();
      } catch (...) {
        error_ = std::current_exception();
      }
    });
  }
  SideTask(const SideTask&) = delete;
  SideTask& operator=(const SideTask&) = delete;
  ~SideTask() {
    if (thread_.joinable()) thread_.join();
  }
  void join() {
    if (thread_.joinable()) thread_.join();
    if (error_) std::rethrow_exception(std::exchange(error_, nullptr));
  }

 private:
  std::thread thread_;
  std::exception_ptr error_;
};

}  // namespace impactdeck::geometry::detail
