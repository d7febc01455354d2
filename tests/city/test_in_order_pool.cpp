// The pool that hands work back in the order it was taken (a city file's buildings, a run
// folder's pooled figures): the order whatever finished first, and its items in flight bounded
// however slow one of them is (issue 47: eval --dir held every later building's series while an
// early one was still being measured, 1.2 GB for 275 buildings).
#include <gtest/gtest.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <condition_variable>
#include <memory>
#include <mutex>
#include <random>
#include <stdexcept>
#include <thread>
#include <vector>

#include "lodrefine/city/in_order_pool.h"

using namespace lodrefine;

namespace {

// The items of one pool run: how many are in flight (taken, not yet given) and the most at once.
struct InFlight {
  std::mutex mutex;
  int now = 0, most = 0;
  void taken() {
    const std::lock_guard<std::mutex> lock(mutex);
    most = std::max(most, ++now);
  }
  void given() {
    const std::lock_guard<std::mutex> lock(mutex);
    --now;
  }
};

}  // namespace

TEST(InOrderPool, GivesItemsInTheOrderTakenWhateverFinishedFirst) {
  for (int jobs : {1, 2, 4}) {
    InFlight flight;
    std::size_t next = 0;
    std::vector<std::size_t> given;
    std::mt19937 rng(7);
    std::vector<int> micros(200);
    for (int& m : micros) m = int(rng() % 2000);  // work of uneven length
    in_order_pool<std::size_t>(
        jobs,
        [&]() -> std::shared_ptr<std::size_t> {
          if (next == micros.size()) return nullptr;
          flight.taken();
          return std::make_shared<std::size_t>(next++);
        },
        [&](std::size_t& k) { std::this_thread::sleep_for(std::chrono::microseconds(micros[k])); },
        [&](std::size_t& k) {
          flight.given();
          given.push_back(k);
        });
    ASSERT_EQ(given.size(), micros.size()) << jobs;
    for (std::size_t i = 0; i < given.size(); ++i) EXPECT_EQ(given[i], i) << jobs;
    EXPECT_LE(flight.most, int(kInOrderItemsPerJob) * jobs) << jobs;
  }
}

// The first item's work waits until the pool has taken all it may take while that item is not
// given; the items in flight then never pass kInOrderItemsPerJob x jobs, not the run's 1,000.
TEST(InOrderPool, ItemsInFlightAreBoundedWhileTheFirstIsSlow) {
  constexpr int kJobs = 2;
  constexpr std::size_t kItems = 1000, kBound = kInOrderItemsPerJob * kJobs;
  InFlight flight;
  std::mutex mutex;
  std::condition_variable cv;
  std::size_t next = 0, given = 0;
  in_order_pool<std::size_t>(
      kJobs,
      [&]() -> std::shared_ptr<std::size_t> {
        const std::lock_guard<std::mutex> lock(mutex);
        if (next == kItems) return nullptr;
        flight.taken();
        auto item = std::make_shared<std::size_t>(next++);
        cv.notify_all();
        return item;
      },
      [&](std::size_t& k) {
        if (k != 0) return;
        std::unique_lock<std::mutex> lock(mutex);  // a bound lower than kBound would time out here
        cv.wait_for(lock, std::chrono::seconds(20), [&] { return next >= kBound; });
      },
      [&](std::size_t& k) {
        flight.given();
        EXPECT_EQ(k, given++);
      });
  EXPECT_EQ(given, kItems);
  // The first item waited for the pool to take kBound items (a lower bound would have timed out
  // there), and no more were taken while it was not given.
  EXPECT_EQ(flight.most, int(kBound));
}

TEST(InOrderPool, AnErrorInTheWorkStopsThePoolAndIsRethrown) {
  for (int jobs : {1, 2}) {
    std::size_t next = 0, given = 0;
    EXPECT_THROW(in_order_pool<std::size_t>(
                     jobs, [&]() { return next == 100 ? nullptr : std::make_shared<std::size_t>(next++); },
                     [&](std::size_t& k) {
                       if (k == 10) throw std::runtime_error("building 10");
                     },
                     [&](std::size_t&) { ++given; }),
                 std::runtime_error);
    EXPECT_LE(given, 10u) << jobs;
  }
}

// TBB frees a token in flight when the pipeline is cancelled only if it waits in a filter's
// buffer, not if it sits in a task the cancellation drops: items the pool handed TBB leaked
// whenever an error stopped it with items still being worked on.
TEST(InOrderPool, AnErrorFreesEveryItemInFlight) {
  struct Counted {
    std::size_t k;
    std::atomic<int>* alive;
    Counted(std::size_t k, std::atomic<int>* alive) : k(k), alive(alive) { ++*alive; }
    ~Counted() { --*alive; }
  };
  constexpr int kJobs = 2;
  constexpr std::size_t kBound = kInOrderItemsPerJob * kJobs;
  for (int round = 0; round < 20; ++round) {
    std::atomic<int> alive{0};
    std::atomic<std::size_t> next{0};
    EXPECT_THROW(in_order_pool<Counted>(
                     kJobs,
                     [&]() -> std::shared_ptr<Counted> {
                       return next == 4 * kBound ? nullptr : std::make_shared<Counted>(next++, &alive);
                     },
                     [&](Counted& item) {
                       // Item 1 fails once the pool is full, with its successors taken and being
                       // worked on.
                       if (item.k == 1) {
                         while (next < kBound) std::this_thread::yield();
                         throw std::runtime_error("building 1");
                       }
                       std::this_thread::sleep_for(std::chrono::milliseconds(2));
                     },
                     [&](Counted&) {}),
                 std::runtime_error);
    ASSERT_EQ(alive.load(), 0) << "round " << round << ": items taken and never freed";
  }
}
