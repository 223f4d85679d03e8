#pragma once
/// The ordered farm skeleton of DESIGN.md section 1, in FastFlow's vocabulary:
///
///   emitter (serial, in order) --> farm of W workers (parallel) --> collector (serial, in order)
///
/// The emitter returns the next item or std::nullopt at end of stream. Workers run the item's
/// tasks; the collector receives items in emission order. At most `tokens` items are in flight
/// (emitted and not yet collected), so a slow collector or farm throttles the emitter instead of
/// building a queue; the collection that gives a token back emits the next item at once, on its
/// own thread. Knows nothing about images.
///
///   sg::par::FarmConfig config{sg::par::Backend::kTbb, /*workers=*/2, /*tokens=*/4,
///                              /*threads=*/2};
///   int next = 0;
///   sg::par::run_ordered_farm(
///       config,
///       [&]() -> std::optional<int> {
///         return next < 100 ? std::optional<int>(next++) : std::nullopt;
///       },
///       [](int x) { return x * x; },                // called by up to W workers at once
///       [&](int sq) { std::cout << sq << "\n"; });  // 0 1 4 9 ... in order
#include <cstddef>
#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <type_traits>
#include <utility>
#include <vector>

#include "sg/par/backend.hpp"
#include "sg/par/metrics.hpp"

namespace sg::par {

/// Settings of an ordered farm. Validate with validate() at the boundary; the run functions throw
/// std::invalid_argument on an invalid config.
struct FarmConfig {
  Backend backend = Backend::kTbb;  ///< kSequential ignores workers, tokens and threads
  int workers = 1;  ///< W >= 1: most farm tasks running at once (FastFlow's farm width)
  int tokens = 4;   ///< >= 1: most items emitted and not yet collected (items in flight)
  int threads = 0;  ///< >= 0: size of the task arena the farm runs in; 0 = current arena
  /// While this returns true, the next item is admitted just in time: a free token alone is not
  /// enough, every item in flight must also have finished its first round (its relay has queued
  /// its second tasks), fewer than `workers` items may be in flight, and no worker may have an
  /// older task to take. For a live source that is
  /// falling behind: the item is then taken from it as late as it can start, so it is fresher,
  /// instead of waiting in the queue while the older items' first rounds take every worker.
  /// Null (the default), or while it returns false: admitted as soon as a token frees, by the
  /// thread that freed it (the next item is emitted right after the collection that gave its
  /// token back, not behind the tasks queued for the workers). Called from the farm's threads,
  /// never concurrently with itself. Ignored by kSequential.
  std::function<bool()> admit_just_in_time{};
  /// The earliest time the item just emitted may start its tasks (a paced camera: the frame's
  /// capture time); called right after each emit(), in the same serial context. An item emitted
  /// before its time waits on a thread of the farm's own, outside the workers, so no worker
  /// sleeps while the items in flight could use it (kSequential sleeps on its one thread). Null
  /// (the default): every item starts as soon as it is emitted.
  std::function<TimePoint()> not_before{};
};

/// Every violation as "par.<field>=<value>: <rule>"; empty when valid.
std::vector<std::string> validate(const FarmConfig& config);

/// Tasks of one item, run by the farm's workers (possibly at once), all finished before the item
/// reaches the collector. Each task typically writes its own part of the item.
using TaskList = std::vector<std::function<void()>>;

namespace detail {

/// Type-erased item, so that the engine (and TBB) lives in one .cpp file.
class FarmItem {
 public:
  virtual ~FarmItem() = default;
};

template <class Item>
class BoxedItem final : public FarmItem {
 public:
  explicit BoxedItem(Item&& value) : value_(std::move(value)) {}
  Item value_;
};

struct FarmCallbacks {
  std::function<std::unique_ptr<FarmItem>()> emit;  ///< nullptr = end of stream
  std::function<TaskList(FarmItem&)> tasks;
  /// Optional serial, in-order stage between the item's first tasks and the collector; returns
  /// the item's second tasks (empty function: no second phase).
  std::function<TaskList(FarmItem&)> relay;
  std::function<void(FarmItem&)> collect;
};

/// Runs the farm; throws std::invalid_argument on an invalid config; rethrows the first
/// exception of a callback after stopping the run.
void run_farm(const FarmConfig& config, const FarmCallbacks& callbacks);

template <class T>
struct IsOptional : std::false_type {};
template <class T>
struct IsOptional<std::optional<T>> : std::true_type {};

/// Boxes the typed callbacks for run_farm; `relay` null: no second round of tasks.
template <class EmitF, class TasksF, class RelayF, class CollectF>
void run_typed_farm(const FarmConfig& config, EmitF& emit, TasksF& make_tasks, RelayF* relay,
                    CollectF& collect) {
  using Emitted = std::invoke_result_t<EmitF&>;
  static_assert(IsOptional<Emitted>::value, "the emitter must return std::optional<Item>");
  using Item = typename Emitted::value_type;
  static_assert(std::is_invocable_r_v<TaskList, TasksF&, Item&>,
                "make_tasks must be callable as TaskList(Item&)");
  static_assert(std::is_invocable_r_v<TaskList, RelayF&, Item&>,
                "relay must be callable as TaskList(Item&)");
  static_assert(std::is_invocable_v<CollectF&, Item&&>, "collect must be callable with Item&&");
  using Boxed = BoxedItem<Item>;

  FarmCallbacks callbacks;
  callbacks.emit = [&emit]() -> std::unique_ptr<FarmItem> {
    Emitted next = emit();
    if (!next) return nullptr;
    return std::make_unique<Boxed>(std::move(*next));
  };
  callbacks.tasks = [&make_tasks](FarmItem& item) -> TaskList {
    return make_tasks(static_cast<Boxed&>(item).value_);
  };
  if (relay) {
    callbacks.relay = [relay](FarmItem& item) -> TaskList {
      return (*relay)(static_cast<Boxed&>(item).value_);
    };
  }
  callbacks.collect = [&collect](FarmItem& item) {
    collect(std::move(static_cast<Boxed&>(item).value_));
  };
  run_farm(config, callbacks);
}

}  // namespace detail

/// Ordered farm where each item yields several tasks that may run at once on different workers
/// (Stereo-Flow mode: one stereo-matching and one optical-flow task per frame).
///
/// * `emit()` -> std::optional<Item>: called serially, never concurrently with itself, only when
///   fewer than `tokens` items are in flight; std::nullopt ends the stream (emit is not called
///   again).
/// * `make_tasks(Item&)` -> TaskList: called right after emit, in the same serial context. The
///   tasks may hold references into the item (it does not move until collected). Each task is
///   called once, by one of at most `workers` concurrent workers; an empty list sends the item
///   straight to the collector.
/// * `collect(Item&&)`: called serially, in emission order, once per item, after all its tasks.
///
/// An exception thrown by any callback stops the run (no new items or tasks start, running tasks
/// finish) and is rethrown from this call on the caller's thread. Returns after the last item was
/// collected.
template <class EmitF, class TasksF, class CollectF>
void run_ordered_farm_tasks(const FarmConfig& config, EmitF&& emit, TasksF&& make_tasks,
                            CollectF&& collect) {
  detail::run_typed_farm(config, emit, make_tasks, static_cast<TasksF*>(nullptr), collect);
}

/// Ordered farm with a second round of tasks per item, FastFlow's pipeline of farm, serial node,
/// farm, collector on one item:
///
///   emit --> tasks (farm) --> relay (serial, in order) --> relay's tasks (farm) --> collect
///
/// As run_ordered_farm_tasks, plus `relay(Item&)` -> TaskList, called serially and in emission
/// order once all first tasks of the item finished; it sees every earlier item's relay but not
/// necessarily its collect (relay and collect of different items may run at once, so they must
/// touch different state). Its tasks run on the same W workers, possibly at once with each other
/// and with other items' tasks; then the item reaches `collect`. The relay is where state that
/// must follow the stream order (a history of past results) is updated cheaply, so that the
/// expensive per-item work on that state can leave the serial collector and run on the farm.
template <class EmitF, class TasksF, class RelayF, class CollectF>
void run_ordered_farm_relay(const FarmConfig& config, EmitF&& emit, TasksF&& make_tasks,
                            RelayF&& relay, CollectF&& collect) {
  detail::run_typed_farm(config, emit, make_tasks, &relay, collect);
}

/// Ordered farm with one task per item: `emit()` -> std::optional<In>, `work(In&&)` -> Mid run by
/// at most `workers` workers at once (so it must be safe to call concurrently), `collect(Mid&&)`
/// in emission order. Same guarantees as run_ordered_farm_tasks().
template <class EmitF, class WorkF, class CollectF>
void run_ordered_farm(const FarmConfig& config, EmitF&& emit, WorkF&& work, CollectF&& collect) {
  using Emitted = std::invoke_result_t<EmitF&>;
  static_assert(detail::IsOptional<Emitted>::value, "the emitter must return std::optional<In>");
  using In = typename Emitted::value_type;
  static_assert(std::is_invocable_v<WorkF&, In&&>, "work must be callable with In&&");
  using Mid = std::invoke_result_t<WorkF&, In&&>;
  static_assert(!std::is_void_v<Mid>, "work must return a value for the collector");
  static_assert(std::is_invocable_v<CollectF&, Mid&&>, "collect must be callable with Mid&&");

  struct Slot {
    std::optional<In> in;
    std::optional<Mid> mid;
  };
  run_ordered_farm_tasks(
      config,
      [&emit]() -> std::optional<Slot> {
        Emitted next = emit();
        if (!next) return std::nullopt;
        return Slot{std::move(next), std::nullopt};
      },
      [&work](Slot& slot) -> TaskList {
        return {[&work, &slot] {
          slot.mid.emplace(work(std::move(*slot.in)));
          slot.in.reset();
        }};
      },
      [&collect](Slot&& slot) { collect(std::move(*slot.mid)); });
}

}  // namespace sg::par
