// Work on a TBB pool handed back in the order it was taken: what keeps a city file's buildings
// and a run folder's pooled figures the same bytes whatever --jobs, with memory bounded by the
// items in flight rather than by the run.
#pragma once
#include <cstddef>
#include <functional>
#include <map>
#include <memory>
#include <mutex>

#include <tbb/global_control.h>
#include <tbb/parallel_pipeline.h>
#include <tbb/task_arena.h>

namespace lodrefine {

// Items in flight per thread of the pool: enough that one slow item does not idle the other
// threads while its successors wait to be given in order.
inline constexpr std::size_t kInOrderItemsPerJob = 16;

// Calls take() for items in order until it returns null, work() on up to `jobs` items at once on
// a pool of exactly `jobs` threads (TBB's parallelism capped at `jobs`, also for 1: nothing
// inside work() runs wider), and give() on the calling order's thread one at a time, in the order
// take() made them. At most kInOrderItemsPerJob x jobs items are alive at once (taken, not yet
// given), whatever their number and however long one takes. An exception from any of the three
// stops the pool and is rethrown here.
template <class Item>
void in_order_pool(int jobs, const std::function<std::shared_ptr<Item>()>& take, const std::function<void(Item&)>& work,
                   const std::function<void(Item&)>& give) {
  jobs = jobs < 1 ? 1 : jobs;
  // TBB caps its threads at the cores (and says so on stderr): --jobs asks for exactly `jobs`.
  const tbb::global_control threads(tbb::global_control::max_allowed_parallelism, std::size_t(jobs));
  if (jobs == 1) {
    while (auto item = take()) {
      work(*item);
      give(*item);
    }
    return;
  }
  // The pool owns the items in flight and TBB passes pointers: when an error cancels the
  // pipeline, TBB frees only the tokens waiting in a filter's buffer, not those in the tasks it
  // drops, so items it owned would leak.
  std::mutex mutex;
  std::map<std::size_t, std::shared_ptr<Item>> in_flight;
  std::size_t taken = 0, given = 0;
  tbb::task_arena arena(jobs);
  arena.execute([&] {
    tbb::parallel_pipeline(
        kInOrderItemsPerJob * std::size_t(jobs),
        tbb::make_filter<void, Item*>(tbb::filter_mode::serial_in_order, [&](tbb::flow_control& fc) -> Item* {
          std::shared_ptr<Item> item = take();
          if (!item) {
            fc.stop();
            return nullptr;
          }
          const std::lock_guard<std::mutex> lock(mutex);
          return in_flight.emplace(taken++, std::move(item)).first->second.get();
        }) & tbb::make_filter<Item*, Item*>(tbb::filter_mode::parallel, [&](Item* item) {
          work(*item);
          return item;
        }) & tbb::make_filter<Item*, void>(tbb::filter_mode::serial_in_order, [&](Item* item) {
          give(*item);
          const std::lock_guard<std::mutex> lock(mutex);
          in_flight.erase(given++);
        }));
  });
}

}  // namespace lodrefine
