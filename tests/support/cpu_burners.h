// Threads that keep the cores busy while a test runs something that must not depend on load.
#pragma once
#include <atomic>
#include <thread>
#include <vector>

namespace lodrefine::fixtures {

class CpuBurners {
 public:
  explicit CpuBurners(int threads) {
    for (int t = 0; t < threads; ++t)
      threads_.emplace_back([this] {
        volatile double x = 1.0;
        while (!stop_) x = x * 1.0000001 + 1e-9;
      });
  }
  CpuBurners(const CpuBurners&) = delete;
  CpuBurners& operator=(const CpuBurners&) = delete;
  ~CpuBurners() { stop(); }
  void stop() {
    stop_ = true;
    for (auto& t : threads_)
      if (t.joinable()) t.join();
  }

 private:
  std::atomic<bool> stop_{false};
  std::vector<std::thread> threads_;
};

}  // namespace lodrefine::fixtures
