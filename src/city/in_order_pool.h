// The city refine's thread pool (cityfile.cpp): items taken in order, worked on at once, given
// back in order. Internal to city.
#pragma once
#include <functional>
#include <memory>

#include <tbb/global_control.h>
#include <tbb/parallel_pipeline.h>
#include <tbb/task_arena.h>

namespace lodrefine {

// Buildings in flight per thread of the pool (see in_order_pool).
constexpr int kItemsPerJob = 16;

// Calls take() for items in order until it returns null, work() on up to `jobs` items at once on
// a pool of `jobs` threads, and give() on the calling order's thread one at a time, in the order
// take() made them. At most kItemsPerJob x jobs items are alive at once: enough that one slow
// building does not idle the other threads while its successors wait to be given in order
// (the crops are in memory anyway; what waits is their refined meshes).
template <class Item>
void in_order_pool(int jobs, const std::function<std::shared_ptr<Item>()>& take, const std::function<void(Item&)>& work,
                   const std::function<void(Item&)>& give) {
  if (jobs <= 1) {
    while (auto item = take()) {
      work(*item);
      give(*item);
    }
    return;
  }
  using Ptr = std::shared_ptr<Item>;
  // TBB caps its threads at the cores (and says so on stderr): --jobs asks for exactly `jobs`.
  const tbb::global_control threads(tbb::global_control::max_allowed_parallelism, std::size_t(jobs));
  tbb::task_arena arena(jobs);
  arena.execute([&] {
    tbb::parallel_pipeline(
        std::size_t(kItemsPerJob * jobs),
        tbb::make_filter<void, Ptr>(tbb::filter_mode::serial_in_order, [&](tbb::flow_control& fc) {
          Ptr item = take();
          if (!item) fc.stop();
          return item;
        }) & tbb::make_filter<Ptr, Ptr>(tbb::filter_mode::parallel, [&](Ptr item) {
          work(*item);
          return item;
        }) & tbb::make_filter<Ptr, void>(tbb::filter_mode::serial_in_order, [&](Ptr item) { give(*item); }));
  });
}

}  // namespace lodrefine
