// Skeleton tests on plain integers (STYLE.md): order kept, each item once, serial stages never
// overlap, empty stream, exceptions propagate, bounds respected; each run with the sequential
// backend and with TBB at 1, 2 and 4 threads.
#include <gtest/gtest.h>
#include <oneapi/tbb/global_control.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cstddef>
#include <memory>
#include <mutex>
#include <numeric>
#include <optional>
#include <ostream>
#include <random>
#include <stdexcept>
#include <string>
#include <thread>
#include <vector>

#include "sg/par/backend.hpp"
#include "sg/par/farm.hpp"
#include "sg/par/jobs.hpp"
#include "sg/par/memory.hpp"
#include "sg/par/metrics.hpp"
#include "sg/par/tiles.hpp"

namespace sg::par {
namespace {

// Lets a 4-thread arena really get 4 threads on a 2-core machine.
const tbb::global_control kAllowFourThreads(tbb::global_control::max_allowed_parallelism, 4);

void pause_us(int us) { std::this_thread::sleep_for(std::chrono::microseconds(us)); }

// Raises `max` to at least `value`.
void raise_max(std::atomic<int>& max, int value) {
  int seen = max.load();
  while (value > seen && !max.compare_exchange_weak(seen, value)) {
  }
}

/// Counts concurrent occupants of a region and remembers the most seen at once.
class Occupancy {
 public:
  void enter() { raise_max(max_, ++inside_); }
  void leave() { --inside_; }
  int max() const { return max_.load(); }

 private:
  std::atomic<int> inside_{0};
  std::atomic<int> max_{0};
};

struct TestError : std::runtime_error {
  explicit TestError(int where) : std::runtime_error("test error"), where_(where) {}
  int where_;
};

struct RunCase {
  Backend backend;
  int threads;
  int workers;
  int tokens;
};

void PrintTo(const RunCase& c, std::ostream* os) {
  *os << to_string(c.backend) << " threads=" << c.threads << " workers=" << c.workers
      << " tokens=" << c.tokens;
}

std::string case_name(const testing::TestParamInfo<RunCase>& info) {
  const RunCase& c = info.param;
  if (c.backend == Backend::kSequential) return "sequential";
  return "tbb_t" + std::to_string(c.threads) + "_w" + std::to_string(c.workers) + "_k" +
         std::to_string(c.tokens);
}

const RunCase kCases[] = {
    {Backend::kSequential, 0, 1, 1}, {Backend::kTbb, 1, 1, 1}, {Backend::kTbb, 1, 2, 4},
    {Backend::kTbb, 2, 1, 3},        {Backend::kTbb, 2, 2, 2}, {Backend::kTbb, 2, 3, 6},
    {Backend::kTbb, 4, 4, 8},        {Backend::kTbb, 4, 2, 3}, {Backend::kTbb, 4, 3, 1},
};

class FarmTest : public testing::TestWithParam<RunCase> {
 protected:
  FarmConfig config() const {
    const RunCase& c = GetParam();
    return FarmConfig{c.backend, c.workers, c.tokens, c.threads};
  }
  // Small deterministic delays that make workers finish out of order.
  static int jitter_us(int x) { return (x * 37) % 5 * 150; }
};

TEST_P(FarmTest, KeepsOrderAndRunsEachItemOnce) {
  constexpr int kItems = 120;
  int next = 0;
  std::vector<std::atomic<int>> calls(kItems);
  std::vector<int> collected;
  run_ordered_farm(
      config(),
      [&]() -> std::optional<int> {
        return next < kItems ? std::optional(next++) : std::nullopt;
      },
      [&](int x) {
        ++calls[static_cast<std::size_t>(x)];
        pause_us(jitter_us(x));
        return 3 * x + 1;
      },
      [&](int y) { collected.push_back(y); });
  ASSERT_EQ(collected.size(), static_cast<std::size_t>(kItems));
  for (int i = 0; i < kItems; ++i) {
    EXPECT_EQ(collected[static_cast<std::size_t>(i)], 3 * i + 1) << "position " << i;
    EXPECT_EQ(calls[static_cast<std::size_t>(i)].load(), 1) << "item " << i;
  }
  EXPECT_EQ(next, kItems);
}

TEST_P(FarmTest, MoveOnlyItems) {
  int next = 0;
  std::vector<int> collected;
  run_ordered_farm(
      config(),
      [&]() -> std::optional<std::unique_ptr<int>> {
        if (next == 30) return std::nullopt;
        return std::make_unique<int>(next++);
      },
      [](std::unique_ptr<int> p) { return std::make_unique<long>(*p * 2L); },
      [&](std::unique_ptr<long> p) { collected.push_back(static_cast<int>(*p)); });
  std::vector<int> expected(30);
  for (int i = 0; i < 30; ++i) expected[static_cast<std::size_t>(i)] = 2 * i;
  EXPECT_EQ(collected, expected);
}

TEST_P(FarmTest, SerialStagesNeverOverlapThemselves) {
  constexpr int kItems = 80;
  Occupancy emitter;
  Occupancy collector;
  int next = 0;
  int count = 0;
  run_ordered_farm(
      config(),
      [&]() -> std::optional<int> {
        emitter.enter();
        pause_us(next % 3 * 100);
        std::optional<int> out = next < kItems ? std::optional(next++) : std::nullopt;
        emitter.leave();
        return out;
      },
      [](int x) { return x; },
      [&](int) {
        collector.enter();
        pause_us(count % 4 * 100);
        ++count;
        collector.leave();
      });
  EXPECT_EQ(emitter.max(), 1);
  EXPECT_EQ(collector.max(), 1);
  EXPECT_EQ(count, kItems);
}

TEST_P(FarmTest, EmptyStreamNeverCallsWorkersOrCollector) {
  int emits = 0;
  int works = 0;
  int collects = 0;
  run_ordered_farm(
      config(),
      [&]() -> std::optional<int> {
        ++emits;
        return std::nullopt;
      },
      [&](int x) {
        ++works;
        return x;
      },
      [&](int) { ++collects; });
  EXPECT_EQ(emits, 1);
  EXPECT_EQ(works, 0);
  EXPECT_EQ(collects, 0);
}

TEST_P(FarmTest, ItemsInFlightBoundedByTokens) {
  constexpr int kItems = 100;
  std::atomic<int> in_flight{0};
  std::atomic<int> max_in_flight{0};
  int next = 0;
  run_ordered_farm(
      config(),
      [&]() -> std::optional<int> {
        if (next == kItems) return std::nullopt;
        raise_max(max_in_flight, ++in_flight);
        return next++;
      },
      [&](int x) {
        pause_us(jitter_us(x));
        return x;
      },
      [&](int) {
        pause_us(50);
        --in_flight;
      });
  EXPECT_EQ(in_flight.load(), 0);
  EXPECT_GE(max_in_flight.load(), 1);
  EXPECT_LE(max_in_flight.load(), GetParam().tokens);
}

TEST_P(FarmTest, ConcurrentWorkersBoundedByW) {
  constexpr int kItems = 60;
  Occupancy workers;
  int next = 0;
  int count = 0;
  run_ordered_farm(
      config(),
      [&]() -> std::optional<int> {
        return next < kItems ? std::optional(next++) : std::nullopt;
      },
      [&](int x) {
        workers.enter();
        pause_us(300);
        workers.leave();
        return x;
      },
      [&](int) { ++count; });
  EXPECT_EQ(count, kItems);
  EXPECT_GE(workers.max(), 1);
  EXPECT_LE(workers.max(), GetParam().workers);
}

// Stereo-Flow mode: two tasks per item (and none for every fifth item), all done before collection.
struct TwoPart {
  int index = 0;
  int stereo = -1;
  int flow = -1;
  int tasks = 2;
};

TEST_P(FarmTest, MultiTaskItemsCompleteBeforeCollection) {
  constexpr int kItems = 70;
  Occupancy tasks_running;
  int next = 0;
  std::vector<int> order;
  run_ordered_farm_tasks(
      config(),
      [&]() -> std::optional<TwoPart> {
        if (next == kItems) return std::nullopt;
        TwoPart p;
        p.index = next++;
        p.tasks = p.index % 5 == 4 ? 0 : 2;
        return p;
      },
      [&](TwoPart& p) -> TaskList {
        if (p.tasks == 0) return {};
        return {[&p, &tasks_running] {
                  tasks_running.enter();
                  pause_us(200 + jitter_us(p.index));
                  p.stereo = 10 * p.index;
                  tasks_running.leave();
                },
                [&p, &tasks_running] {
                  tasks_running.enter();
                  pause_us(100);
                  p.flow = 10 * p.index + 1;
                  tasks_running.leave();
                }};
      },
      [&](TwoPart&& p) {
        order.push_back(p.index);
        if (p.tasks == 2) {
          EXPECT_EQ(p.stereo, 10 * p.index) << "item " << p.index;
          EXPECT_EQ(p.flow, 10 * p.index + 1) << "item " << p.index;
        } else {
          EXPECT_EQ(p.stereo, -1);
          EXPECT_EQ(p.flow, -1);
        }
      });
  std::vector<int> expected(kItems);
  std::iota(expected.begin(), expected.end(), 0);
  EXPECT_EQ(order, expected);
  EXPECT_LE(tasks_running.max(), GetParam().workers);
}

// The relay farm: the relay sees items in order after their first tasks, keeps a running history
// (what the Stereo-Flow detector does with past maps), and its tasks finish before collection.
struct Relayed {
  int index = 0;
  int first = -1;          // written by the first task
  int history_sum = -1;    // the relay's running sum of `first` up to this item
  std::vector<int> parts;  // written by the relay's tasks, one slot each
};

TEST_P(FarmTest, RelayRunsInOrderAndItsTasksFinishBeforeCollection) {
  constexpr int kItems = 60;
  Occupancy tasks_running;
  Occupancy relays_running;
  int next = 0;
  int running_sum = 0;
  std::vector<int> relay_order;
  std::vector<int> order;
  run_ordered_farm_relay(
      config(),
      [&]() -> std::optional<Relayed> {
        if (next == kItems) return std::nullopt;
        Relayed r;
        r.index = next++;
        return r;
      },
      [&](Relayed& r) -> TaskList {
        if (r.index % 7 == 6) return {};  // no first task: still relayed
        return {[&r, &tasks_running] {
          tasks_running.enter();
          pause_us(100 + jitter_us(r.index));
          r.first = 3 * r.index;
          tasks_running.leave();
        }};
      },
      [&](Relayed& r) -> TaskList {
        relays_running.enter();
        relay_order.push_back(r.index);
        running_sum += std::max(r.first, 0);
        r.history_sum = running_sum;
        const int parts = r.index % 5 == 4 ? 0 : 3;
        r.parts.assign(static_cast<std::size_t>(parts), -1);
        TaskList tasks;
        for (int t = 0; t < parts; ++t) {
          tasks.push_back([&r, t, &tasks_running] {
            tasks_running.enter();
            pause_us(50 + jitter_us(r.index + t));
            r.parts[static_cast<std::size_t>(t)] = r.history_sum + t;
            tasks_running.leave();
          });
        }
        relays_running.leave();
        return tasks;
      },
      [&](Relayed&& r) {
        order.push_back(r.index);
        for (std::size_t t = 0; t < r.parts.size(); ++t) {
          EXPECT_EQ(r.parts[t], r.history_sum + static_cast<int>(t)) << "item " << r.index;
        }
      });
  std::vector<int> expected(kItems);
  std::iota(expected.begin(), expected.end(), 0);
  EXPECT_EQ(relay_order, expected);
  EXPECT_EQ(order, expected);
  EXPECT_EQ(relays_running.max(), 1);
  EXPECT_LE(tasks_running.max(), GetParam().workers);
  int sum = 0;
  for (int i = 0; i < kItems; ++i) sum += i % 7 == 6 ? 0 : 3 * i;
  EXPECT_EQ(running_sum, sum);
}

/// Runs a relay farm whose first tasks take `first_us` and counts the emitter calls made while an
/// earlier item's first round was not over (emitted, its relay not yet called). `most_in_flight`:
/// the most items emitted and not collected that an emitter call found.
int emits_during_first_rounds(FarmConfig config, int items, int first_us,
                              int* most_in_flight = nullptr) {
  std::mutex mutex;
  int open = 0, overlapping = 0, next = 0, in_flight = 0, most = 0;
  std::vector<int> order;
  run_ordered_farm_relay(
      config,
      [&]() -> std::optional<Relayed> {
        if (next == items) return std::nullopt;
        const std::lock_guard<std::mutex> lock(mutex);
        overlapping += open > 0;
        ++open;
        most = std::max(most, in_flight++);
        Relayed r;
        r.index = next++;
        return r;
      },
      [&](Relayed& r) -> TaskList {
        if (r.index % 7 == 6) return {};  // no first task
        return {[&r, first_us] {
                  pause_us(first_us);
                  r.first = r.index;
                },
                [first_us] { pause_us(first_us / 2); }};
      },
      [&](Relayed& r) -> TaskList {
        {
          const std::lock_guard<std::mutex> lock(mutex);
          --open;
        }
        if (r.index % 5 == 4) return {};  // no relay task
        return {[&r] { r.history_sum = r.first; }, [] { pause_us(200); }};
      },
      [&](Relayed&& r) {
        {
          const std::lock_guard<std::mutex> lock(mutex);
          --in_flight;
        }
        order.push_back(r.index);
        if (r.index % 7 != 6 && r.index % 5 != 4) {
          EXPECT_EQ(r.history_sum, r.index);
        }
      });
  std::vector<int> expected(static_cast<std::size_t>(items));
  std::iota(expected.begin(), expected.end(), 0);
  EXPECT_EQ(order, expected);
  if (most_in_flight) *most_in_flight = most;
  return overlapping;
}

TEST_P(FarmTest, JustInTimeAdmissionWaitsForTheFirstRoundsInFlight) {
  FarmConfig config = this->config();
  config.admit_just_in_time = [] { return true; };
  int most_in_flight = 0;
  EXPECT_EQ(emits_during_first_rounds(config, 40, 300 + jitter_us(3), &most_in_flight), 0);
  // Fewer than W items in flight when the next is emitted, whatever the tokens allow.
  EXPECT_LT(most_in_flight, std::max(1, GetParam().workers));
}

TEST(FarmAdmissionTest, EagerAdmissionEmitsDuringFirstRounds) {
  // Two tokens: without just-in-time admission (or while it answers no), the second item is
  // emitted as soon as the first is, long before the first's 20 ms first round is over.
  FarmConfig config{Backend::kTbb, 2, 2, 2};
  int most_in_flight = 0;
  EXPECT_GT(emits_during_first_rounds(config, 6, 20000, &most_in_flight), 0);
  EXPECT_EQ(most_in_flight, 1);
  config.admit_just_in_time = [] { return false; };
  EXPECT_GT(emits_during_first_rounds(config, 6, 20000), 0);
  config.admit_just_in_time = [] { return true; };
  EXPECT_EQ(emits_during_first_rounds(config, 6, 20000), 0);
}

TEST(FarmAdmissionTest, TheEmitterIsNotCalledAgainAfterTheEnd) {
  // A collection emits on its own thread while a just-in-time leave emits on a worker: two
  // emissions can race. The one that finds the stream over must not call the emitter again
  // (whose end, here, takes 2 ms, so that the other is waiting by then).
  for (int run = 0; run < 40; ++run) {
    FarmConfig config{Backend::kTbb, 2, 3, 2};
    std::atomic<int> asked{0};
    config.admit_just_in_time = [&asked] { return asked.fetch_add(1) % 2 == 0; };
    int next = 0;
    int calls_after_end = 0;
    bool over = false;
    run_ordered_farm_tasks(
        config,
        [&]() -> std::optional<int> {
          if (over) ++calls_after_end;
          if (next == 12) {
            pause_us(2000);
            over = true;
            return std::nullopt;
          }
          return next++;
        },
        [](int&) -> TaskList { return {[] { pause_us(300); }}; }, [](int&&) {});
    EXPECT_EQ(calls_after_end, 0) << "run " << run;
  }
}

/// What ran, in the order it ran, from any thread.
class EventLog {
 public:
  void note(const std::string& what) {
    const std::lock_guard<std::mutex> lock(mutex_);
    events_.push_back(what);
  }
  /// Where `what` stands (events().size() when absent).
  std::ptrdiff_t at(const std::string& what) const {
    return std::find(events_.begin(), events_.end(), what) - events_.begin();
  }
  const std::vector<std::string>& events() const { return events_; }

 private:
  std::mutex mutex_;
  std::vector<std::string> events_;
};

TEST(FarmAdmissionTest, ATokenComesBackAsTheNextItemNotBehindTheQueuedTasks) {
  // One worker, two tokens: item 1's task is queued while item 0's runs. When item 0 is
  // collected its token emits item 2 at once, on the thread that collected it, before the worker
  // takes item 1's task; just-in-time admission configured but answering no changes nothing (its
  // leave used to wait in the farm's queue behind item 1's task, so a paced camera's frame was
  // taken a task later and lost).
  for (const bool configured : {false, true}) {
    FarmConfig config{Backend::kTbb, 1, 2, 2};
    if (configured) config.admit_just_in_time = [] { return false; };
    EventLog log;
    auto note = [&log](const std::string& what) { log.note(what); };
    int next = 0;
    run_ordered_farm_tasks(
        config,
        [&]() -> std::optional<int> {
          if (next == 4) return std::nullopt;
          note("emit " + std::to_string(next));
          return next++;
        },
        [&](int& item) -> TaskList {
          return {[&note, item] {
            note("task " + std::to_string(item) + " starts");
            pause_us(30000);
          }};
        },
        [&](int&& item) { note("collect " + std::to_string(item)); });
    const std::string trace = ::testing::PrintToString(log.events());
    ASSERT_EQ(log.events().size(), 12u) << trace;
    EXPECT_LT(log.at("collect 0"), log.at("emit 2")) << trace;  // the token came from item 0
    EXPECT_LT(log.at("emit 2"), log.at("task 1 starts")) << configured << trace;
    EXPECT_LT(log.at("emit 3"), log.at("task 2 starts")) << configured << trace;
  }
}

TEST_P(FarmTest, NoItemStartsItsTasksBeforeItsTime) {
  // Items emitted at once, each due 3 ms after the one before (a paced camera's capture times).
  constexpr int kItems = 12;
  const TimePoint t0 = now() + std::chrono::milliseconds(5);
  auto due = [t0](int k) { return t0 + std::chrono::milliseconds(3 * k); };
  FarmConfig config = this->config();
  int next = 0;
  config.not_before = [&] { return due(next - 1); };  // right after emit: the item just emitted
  std::vector<TimePoint> started(kItems);
  std::vector<int> collected;
  run_ordered_farm_tasks(
      config,
      [&]() -> std::optional<int> {
        return next < kItems ? std::optional(next++) : std::nullopt;
      },
      [&](int& x) -> TaskList {
        return {[&started, &x] { started[static_cast<std::size_t>(x)] = now(); }};
      },
      [&](int&& x) { collected.push_back(x); });
  ASSERT_EQ(collected.size(), static_cast<std::size_t>(kItems));
  for (int k = 0; k < kItems; ++k) EXPECT_GE(started[static_cast<std::size_t>(k)], due(k)) << k;
}

TEST(FarmHoldTest, AnItemWaitingForItsTimeLeavesBothWorkersToTheItemInFlight) {
  // Item 0 (due in 30 ms) has two tasks that must run at once; item 1, emitted on the second
  // token, is due only after the tasks' patience has run out. Were item 1 waited for on one of
  // the two threads, item 0's tasks would have one thread between them and could not meet.
  FarmConfig config{Backend::kTbb, 2, 2, 2};
  const TimePoint t0 = now();
  const std::chrono::milliseconds patience(1000);
  int next = 0;
  config.not_before = [&] {
    return next == 1 ? t0 + std::chrono::milliseconds(30) : t0 + patience + patience / 5;
  };
  std::atomic<int> arrived{0};
  std::atomic<bool> met{true};
  auto meet = [&] {
    ++arrived;
    const TimePoint give_up = now() + patience;
    while (arrived.load() < 2 && now() < give_up) pause_us(100);
    if (arrived.load() < 2) met = false;
  };
  int collected = 0;
  run_ordered_farm_tasks(
      config,
      [&]() -> std::optional<int> { return next < 2 ? std::optional(next++) : std::nullopt; },
      [&](int& x) -> TaskList {
        if (x == 0) return {meet, meet};
        return {[] {}};
      },
      [&](int&&) { ++collected; });
  EXPECT_TRUE(met.load());
  EXPECT_EQ(collected, 2);
}

TEST_P(FarmTest, EmitterExceptionWhileAnItemWaitsForItsTime) {
  // Item 1 waits 200 ms for its time when the emitter throws at item 2: the run stops and
  // rethrows instead of hanging or starting what was waiting.
  const TimePoint t0 = now();
  FarmConfig config = this->config();
  int next = 0;
  config.not_before = [&] { return t0 + std::chrono::milliseconds(next == 2 ? 200 : 0); };
  std::atomic<int> collected{0};
  EXPECT_THROW(run_ordered_farm_tasks(
                   config,
                   [&]() -> std::optional<int> {
                     if (next == 2) throw TestError(next);
                     return std::optional(next++);
                   },
                   [](int&) -> TaskList { return {[] {}}; }, [&](int&&) { ++collected; }),
               TestError);
  EXPECT_LE(collected.load(), 2);
}

TEST_P(FarmTest, RelayTaskExceptionPropagates) {
  int next = 0;
  int collected = 0;
  EXPECT_THROW(run_ordered_farm_relay(
                   config(),
                   [&]() -> std::optional<int> {
                     return next < 500 ? std::optional(next++) : std::nullopt;
                   },
                   [](int&) -> TaskList { return {[] { pause_us(20); }}; },
                   [](int& x) -> TaskList {
                     return {[&x] {
                       if (x == 37) throw TestError(x);
                     }};
                   },
                   [&](int&&) { ++collected; }),
               TestError);
  EXPECT_LT(collected, 500);
}

// Tiles nested inside farm workers: a worker waiting in parallel_for must not deadlock the farm.
TEST_P(FarmTest, NestedTilesInsideWorkers) {
  constexpr int kItems = 20;
  constexpr int kRows = 37;
  int next = 0;
  std::vector<long> sums;
  run_ordered_farm(
      config(),
      [&]() -> std::optional<int> {
        return next < kItems ? std::optional(next++) : std::nullopt;
      },
      [&](int x) {
        std::vector<long> rows(kRows, 0);
        parallel_for_tiles(
            kRows, 4,
            [&](int, int begin, int end) {
              for (int r = begin; r < end; ++r) rows[static_cast<std::size_t>(r)] = r * x;
              pause_us(100);
            },
            GetParam().backend);
        return std::accumulate(rows.begin(), rows.end(), 0L);
      },
      [&](long s) { sums.push_back(s); });
  ASSERT_EQ(sums.size(), static_cast<std::size_t>(kItems));
  for (int x = 0; x < kItems; ++x) {
    EXPECT_EQ(sums[static_cast<std::size_t>(x)], static_cast<long>(x) * kRows * (kRows - 1) / 2);
  }
}

enum class Thrower { kEmitter, kWorker, kCollector, kTask };

void run_throwing(const FarmConfig& config, Thrower where, int at, int* collected) {
  constexpr int kItems = 1000;
  int next = 0;
  auto emit = [&]() -> std::optional<int> {
    if (where == Thrower::kEmitter && next == at) throw TestError(next);
    return next < kItems ? std::optional(next++) : std::nullopt;
  };
  auto collect = [&](int) { ++*collected; };
  if (where == Thrower::kTask) {
    run_ordered_farm_tasks(
        config, emit,
        [&](int& x) -> TaskList {
          return {[] { pause_us(50); },
                  [&x, at] {
                    if (x == at) throw TestError(x);
                  }};
        },
        collect);
    return;
  }
  run_ordered_farm(
      config, emit,
      [&](int x) {
        pause_us(50);
        if (where == Thrower::kWorker && x == at) throw TestError(x);
        return x;
      },
      [&](int x) {
        if (where == Thrower::kCollector && x == at) throw TestError(x);
        collect(x);
      });
}

TEST_P(FarmTest, ExceptionsStopTheRunAndPropagate) {
  for (Thrower where : {Thrower::kEmitter, Thrower::kWorker, Thrower::kCollector, Thrower::kTask}) {
    for (int at : {0, 1, 13}) {
      int collected = 0;
      try {
        run_throwing(config(), where, at, &collected);
        ADD_FAILURE() << "no exception, thrower " << static_cast<int>(where) << " at " << at;
      } catch (const TestError& e) {
        EXPECT_EQ(e.where_, at);
      }
      // Items after the failing one never reach the collector.
      EXPECT_LE(collected, at) << "thrower " << static_cast<int>(where) << " at " << at;
    }
  }
  // The machinery is reusable after a failed run.
  int collected = 0;
  run_throwing(config(), Thrower::kWorker, -1, &collected);
  EXPECT_EQ(collected, 1000);
}

INSTANTIATE_TEST_SUITE_P(Backends, FarmTest, testing::ValuesIn(kCases), case_name);

// A worker that comes free takes the oldest item's task: item 0's relay task, queued after item 1's
// two first tasks (item 0's first task sleeps until item 1 is emitted), runs before the second of
// them; first in, first out runs both of item 1's first. Whether the relay's task comes before or
// after item 1's first one depends on when the relay runs, so only the order that first in,
// first out gets wrong is checked. One worker, two items in flight, two threads so that the
// relay runs while the worker sleeps.
TEST(FarmOrderTest, AFreeWorkerTakesTheOldestItemsTaskFirst) {
  const FarmConfig config{Backend::kTbb, 1, 2, 2};
  EventLog log;
  auto note = [&log](const std::string& what) { log.note(what); };
  int next = 0;
  run_ordered_farm_relay(
      config,
      [&]() -> std::optional<int> { return next < 2 ? std::optional(next++) : std::nullopt; },
      [&](int& item) -> TaskList {
        if (item == 0) {
          return {[&] {
            pause_us(100000);  // item 1 is emitted meanwhile: its tasks queue before relay 0's
            note("first 0");
          }};
        }
        return {[&] {
                  pause_us(200000);  // long enough for item 0's relay to queue its task
                  note("first 1a");
                },
                [&] { note("first 1b"); }};
      },
      [&](int& item) -> TaskList {
        return {[&note, item] { note("relay " + std::to_string(item)); }};
      },
      [](int&&) {});
  const std::vector<std::string>& ran = log.events();
  ASSERT_EQ(ran.size(), 5u);
  EXPECT_EQ(ran.front(), "first 0");
  EXPECT_EQ(ran.back(), "relay 1");
  EXPECT_LT(log.at("relay 0"), log.at("first 1b")) << ::testing::PrintToString(ran);
}

TEST(FarmConfigTest, ValidateNamesEachBadField) {
  EXPECT_TRUE(validate(FarmConfig{}).empty());
  const std::vector<std::string> problems = validate(FarmConfig{Backend::kTbb, 0, 0, -1});
  ASSERT_EQ(problems.size(), 3u);
  EXPECT_EQ(problems[0], "par.workers=0: must be >= 1");
  EXPECT_EQ(problems[1], "par.tokens=0: must be >= 1");
  EXPECT_EQ(problems[2], "par.threads=-1: must be >= 0 (0 = all cores)");
}

TEST(FarmConfigTest, RunRejectsInvalidConfig) {
  for (Backend backend : {Backend::kSequential, Backend::kTbb}) {
    bool emitted = false;
    EXPECT_THROW(run_ordered_farm(
                     FarmConfig{backend, 1, 0, 0},
                     [&]() -> std::optional<int> {
                       emitted = true;
                       return std::nullopt;
                     },
                     [](int x) { return x; }, [](int) {}),
                 std::invalid_argument);
    EXPECT_FALSE(emitted);
  }
}

TEST(BackendTest, NamesAndThreads) {
  EXPECT_STREQ(to_string(Backend::kSequential), "sequential");
  EXPECT_STREQ(to_string(Backend::kTbb), "tbb");
  EXPECT_GE(default_threads(), 1);
}

// ---------------------------------------------------------------------------------------------
// Tiles

TEST(TilesTest, TilesPartitionRows) {
  for (int rows = 0; rows <= 70; ++rows) {
    for (int tiles = 1; tiles <= 80; ++tiles) {
      const int count = tile_count(rows, tiles);
      ASSERT_EQ(count, rows == 0 ? 0 : std::min(rows, tiles)) << rows << " rows, " << tiles;
      int expected_begin = 0;
      int smallest = rows + 1;
      int largest = -1;
      for (int t = 0; t < count; ++t) {
        const RowRange r = tile_rows(rows, tiles, t);
        ASSERT_EQ(r.begin, expected_begin) << rows << " rows, " << tiles << " tiles, tile " << t;
        ASSERT_GE(r.size(), 1);
        smallest = std::min(smallest, r.size());
        largest = std::max(largest, r.size());
        expected_begin = r.end;
      }
      ASSERT_EQ(expected_begin, rows) << rows << " rows, " << tiles << " tiles";
      if (count > 0) {
        ASSERT_LE(largest - smallest, 1) << rows << " rows, " << tiles << " tiles";
      }
    }
  }
}

TEST(TilesTest, TileRowsExamples) {
  EXPECT_EQ(tile_rows(10, 3, 0), (RowRange{0, 4}));
  EXPECT_EQ(tile_rows(10, 3, 1), (RowRange{4, 7}));
  EXPECT_EQ(tile_rows(10, 3, 2), (RowRange{7, 10}));
  EXPECT_EQ(tile_rows(3, 8, 2), (RowRange{2, 3}));  // tiles clamped to rows
  EXPECT_EQ(tile_count(3, 8), 3);
  EXPECT_EQ(tile_count(5, 0), 1);  // tiles < 1 counts as 1
  EXPECT_EQ(tile_rows(5, 0, 0), (RowRange{0, 5}));
  EXPECT_TRUE(tile_rows(10, 3, 3).empty());  // out-of-range tile index
  EXPECT_EQ(tile_count(0, 4), 0);
}

struct TileCase {
  Backend backend;
  int threads;
};

class ParallelTilesTest : public testing::TestWithParam<TileCase> {};

TEST_P(ParallelTilesTest, EachRowOnceInItsTile) {
  const TileCase c = GetParam();
  run_in_arena(c.threads, [&] {
    for (int rows : {0, 1, 2, 3, 7, 31, 64, 101}) {
      for (int tiles : {1, 2, 3, 4, 5, 8, 13, 200}) {
        std::vector<std::atomic<int>> visits(static_cast<std::size_t>(rows));
        std::atomic<int> calls{0};
        std::atomic<int> mismatches{0};
        parallel_for_tiles(
            rows, tiles,
            [&](int t, int begin, int end) {
              ++calls;
              if (tile_rows(rows, tiles, t) != RowRange{begin, end}) ++mismatches;
              for (int r = begin; r < end; ++r) ++visits[static_cast<std::size_t>(r)];
              pause_us(20);
            },
            c.backend);
        EXPECT_EQ(calls.load(), tile_count(rows, tiles)) << rows << " rows, " << tiles;
        EXPECT_EQ(mismatches.load(), 0) << rows << " rows, " << tiles;
        for (int r = 0; r < rows; ++r) {
          ASSERT_EQ(visits[static_cast<std::size_t>(r)].load(), 1) << "row " << r << " of " << rows;
        }
      }
    }
  });
}

TEST_P(ParallelTilesTest, PlainWritesVisibleAfterReturn) {
  const TileCase c = GetParam();
  run_in_arena(c.threads, [&] {
    std::vector<int> out(257, -1);
    parallel_for_tiles(
        257, 6,
        [&](int t, int begin, int end) {
          for (int r = begin; r < end; ++r) out[static_cast<std::size_t>(r)] = 1000 * t + r;
        },
        c.backend);
    for (int t = 0; t < 6; ++t) {
      const RowRange range = tile_rows(257, 6, t);
      for (int r = range.begin; r < range.end; ++r) {
        ASSERT_EQ(out[static_cast<std::size_t>(r)], 1000 * t + r);
      }
    }
  });
}

TEST_P(ParallelTilesTest, ExceptionPropagates) {
  const TileCase c = GetParam();
  run_in_arena(c.threads, [&] {
    try {
      parallel_for_tiles(
          50, 5,
          [](int t, int, int) {
            if (t == 3) throw TestError(t);
          },
          c.backend);
      ADD_FAILURE() << "no exception";
    } catch (const TestError& e) {
      EXPECT_EQ(e.where_, 3);
    }
  });
}

INSTANTIATE_TEST_SUITE_P(Backends, ParallelTilesTest,
                         testing::Values(TileCase{Backend::kSequential, 0},
                                         TileCase{Backend::kTbb, 1}, TileCase{Backend::kTbb, 2},
                                         TileCase{Backend::kTbb, 4}),
                         [](const testing::TestParamInfo<TileCase>& info) {
                           return info.param.backend == Backend::kSequential
                                      ? std::string("sequential")
                                      : "tbb_t" + std::to_string(info.param.threads);
                         });

TEST(ArenaTest, LimitsConcurrencyToThreads) {
  for (int threads : {1, 2}) {
    Occupancy tiles;
    run_in_arena(threads, [&] {
      parallel_for_tiles(64, 64, [&](int, int, int) {
        tiles.enter();
        pause_us(200);
        tiles.leave();
      });
    });
    EXPECT_GE(tiles.max(), 1);
    EXPECT_LE(tiles.max(), threads);
  }
}

// ---------------------------------------------------------------------------------------------
// Metrics

TEST(ForEachJob, RunsEveryJobOnceOnAtMostTheThreadsAsked) {
  for (const int threads : {1, 2, 3, 0}) {
    for (const int count : {0, 1, 2, 17}) {
      std::vector<std::atomic<int>> runs(static_cast<size_t>(count));
      std::atomic<int> running{0}, most{0};
      int done = 0;  // done() is never called by two threads at once
      par::for_each_job(
          count, threads,
          [&](int i) {
            const int now = ++running;
            int seen = most.load();
            while (now > seen && !most.compare_exchange_weak(seen, now)) {
            }
            std::this_thread::sleep_for(std::chrono::milliseconds(i % 3));
            ++runs[static_cast<size_t>(i)];
            --running;
          },
          [&] { ++done; });
      for (int i = 0; i < count; ++i) EXPECT_EQ(runs[static_cast<size_t>(i)], 1) << i;
      EXPECT_EQ(done, count);
      EXPECT_LE(most.load(), threads > 0 ? threads : par::default_threads());
    }
  }
}

TEST(ForEachJob, TheFirstErrorStopsTheHandingOutAndIsRethrown) {
  // One thread: nothing after the failed job starts.
  int started = 0, done = 0;
  const auto job = [&](int i) {
    ++started;
    if (i == 3) throw std::runtime_error("job 3");
  };
  EXPECT_THROW(par::for_each_job(1000, 1, job, [&] { ++done; }), std::runtime_error);
  EXPECT_EQ(started, 4);
  EXPECT_EQ(done, 3);
  // Two threads: how far the other one got depends on the scheduler (on a loaded machine it
  // may finish every other job before the failing one throws), but the error is rethrown and
  // every job that ended without one was reported.
  std::atomic<int> started2{0};
  int done2 = 0;
  EXPECT_THROW(par::for_each_job(
                   1000, 2,
                   [&](int i) {
                     ++started2;
                     if (i == 3) throw std::runtime_error("job 3");
                   },
                   [&] { ++done2; }),
               std::runtime_error);
  EXPECT_EQ(done2, started2.load() - 1);
}

TEST(LatencyStatsTest, NearestRankPercentiles) {
  std::vector<double> values(20);
  std::iota(values.begin(), values.end(), 1.0);  // 1 .. 20 ms
  std::mt19937 rng(42);
  std::shuffle(values.begin(), values.end(), rng);
  LatencyStats stats;
  for (double v : values) stats.add(v);
  EXPECT_EQ(stats.count(), 20u);
  EXPECT_DOUBLE_EQ(stats.p50(), 10.0);  // rank ceil(0.50 * 20) = 10
  EXPECT_DOUBLE_EQ(stats.p95(), 19.0);  // rank 19
  EXPECT_DOUBLE_EQ(stats.p99(), 20.0);  // rank ceil(19.8) = 20
  EXPECT_DOUBLE_EQ(stats.percentile(0.0), 1.0);
  EXPECT_DOUBLE_EQ(stats.percentile(5.0), 1.0);  // rank 1
  EXPECT_DOUBLE_EQ(stats.percentile(6.0), 2.0);  // rank ceil(1.2) = 2
  EXPECT_DOUBLE_EQ(stats.percentile(100.0), 20.0);
  EXPECT_DOUBLE_EQ(stats.min(), 1.0);
  EXPECT_DOUBLE_EQ(stats.max(), 20.0);
  EXPECT_DOUBLE_EQ(stats.mean(), 10.5);
  EXPECT_DOUBLE_EQ(stats.sum(), 210.0);
  // Adding after a query re-sorts.
  stats.add(0.5);
  EXPECT_DOUBLE_EQ(stats.percentile(0.0), 0.5);
  EXPECT_DOUBLE_EQ(stats.p50(), 10.0);  // rank ceil(10.5) = 11 of 0.5, 1 .. 20
  EXPECT_EQ(stats.samples().back(), 0.5);
}

TEST(LatencyStatsTest, SmallAndEmpty) {
  LatencyStats stats;
  EXPECT_TRUE(stats.empty());
  EXPECT_EQ(stats.p50(), 0.0);
  EXPECT_EQ(stats.max(), 0.0);
  EXPECT_EQ(stats.mean(), 0.0);
  stats.add(7.5);
  EXPECT_EQ(stats.p50(), 7.5);
  EXPECT_EQ(stats.p99(), 7.5);
  EXPECT_EQ(stats.min(), 7.5);
  stats.add(2.5);
  EXPECT_EQ(stats.p50(), 2.5);  // rank 1 of {2.5, 7.5}
  EXPECT_EQ(stats.p95(), 7.5);
  EXPECT_EQ(stats.mean(), 5.0);
  stats.clear();
  EXPECT_EQ(stats.count(), 0u);
  EXPECT_EQ(stats.max(), 0.0);
}

TEST(ClockTest, ElapsedIsSignedMilliseconds) {
  const TimePoint t0 = now();
  const TimePoint t1 = t0 + std::chrono::microseconds(2500);
  EXPECT_DOUBLE_EQ(elapsed_ms(t0, t1), 2.5);
  EXPECT_DOUBLE_EQ(elapsed_ms(t1, t0), -2.5);
  const TimePoint a = now();
  const TimePoint b = now();
  EXPECT_GE(elapsed_ms(a, b), 0.0);  // monotonic
  Stopwatch watch;
  EXPECT_GE(watch.elapsed_ms(), 0.0);
}

TEST(PrefaultHeap, TouchesWholeBlocksUpToTheRequestAndNothingForZero) {
  EXPECT_EQ(prefault_heap(0), 0u);
  EXPECT_EQ(prefault_heap(1, 1 << 20), std::size_t{1} << 20);
  EXPECT_EQ(prefault_heap((5u << 20) + 1, 1 << 20), std::size_t{6} << 20);
  EXPECT_EQ(prefault_heap(10000, 100), 12288u);  // blocks of at least a page
}

}  // namespace
}  // namespace sg::par
