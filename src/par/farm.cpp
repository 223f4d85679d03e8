#include "sg/par/farm.hpp"

#include <oneapi/tbb/flow_graph.h>
#include <oneapi/tbb/task_arena.h>

#include <atomic>
#include <cstddef>
#include <mutex>
#include <stdexcept>
#include <tuple>

namespace sg::par {

std::vector<std::string> validate(const FarmConfig& config) {
  std::vector<std::string> problems;
  if (config.workers < 1) {
    problems.push_back("par.workers=" + std::to_string(config.workers) + ": must be >= 1");
  }
  if (config.tokens < 1) {
    problems.push_back("par.tokens=" + std::to_string(config.tokens) + ": must be >= 1");
  }
  if (config.threads < 0) {
    problems.push_back("par.threads=" + std::to_string(config.threads) +
                       ": must be >= 0 (0 = all cores)");
  }
  return problems;
}

namespace detail {
namespace {

namespace flow = tbb::flow;

// Happens-before edges that ThreadSanitizer can see. Debian's libtbb is not built with
// -fsanitize=thread, so TSan cannot see the ordering TBB provides when it spawns, steals and joins
// tasks. run_graph calls handoff_start() before the graph runs and handoff_join() after it; every
// node body opens a HandoffScope: the caller's set-up is ordered before each body and each body
// before the caller's next use of that memory. Two atomics, each written on one side only, so no
// edge links two bodies: TSan still reports two farm tasks touching the same memory even when they
// did not overlap in time. Globals, so that a body reaches them without first reading its own
// closure (which the caller wrote). One atomic operation per body, i.e. per item.
std::atomic<std::size_t> tsan_started{0};   // callers release, bodies acquire
std::atomic<std::size_t> tsan_finished{0};  // bodies release, callers acquire

void handoff_start() { tsan_started.fetch_add(1, std::memory_order_release); }
void handoff_join() { (void)tsan_finished.load(std::memory_order_acquire); }

class HandoffScope {
 public:
  HandoffScope() { (void)tsan_started.load(std::memory_order_acquire); }
  ~HandoffScope() { tsan_finished.fetch_add(1, std::memory_order_release); }
  HandoffScope(const HandoffScope&) = delete;
  HandoffScope& operator=(const HandoffScope&) = delete;
};

void run_sequential(const FarmCallbacks& cb) {
  while (std::unique_ptr<FarmItem> item = cb.emit()) {
    for (const std::function<void()>& task : cb.tasks(*item)) task();
    if (cb.relay) {
      for (const std::function<void()>& task : cb.relay(*item)) task();
    }
    cb.collect(*item);
  }
}

// One item in flight. The graph passes only slot numbers (trivially copyable messages); the
// slots live in a ring of `tokens` entries owned by run_graph. Item `seq` uses slot
// seq % tokens: the emitter only runs while holding a token and a token comes back only after the
// collector is done with its item, so item seq - tokens has left its slot before item seq is
// emitted (the `free` flag checks this and makes it visible to ThreadSanitizer).
struct Slot {
  std::unique_ptr<FarmItem> item;
  TaskList tasks;
  std::size_t seq = 0;                    // emission index, the sequencer's key
  std::atomic<std::size_t> published{0};  // seq + 1 once the emitter filled the slot
  std::atomic<std::size_t> remaining{0};  // tasks not yet finished
  std::atomic<std::size_t> relayed{0};    // seq + 1 once the relay replaced the tasks
  std::atomic<bool> free{true};
};

struct TaskMsg {
  std::size_t seq = 0;
  std::size_t task = 0;
  int phase = 0;  // 0: the emitter's tasks, 1: the relay's
};

void run_graph(const FarmConfig& config, const FarmCallbacks& cb) {
  const auto tokens = static_cast<std::size_t>(config.tokens);
  std::vector<Slot> ring(tokens);
  auto slot_of = [&ring, tokens](std::size_t seq) -> Slot& { return ring[seq % tokens]; };
  std::atomic<bool> ended{false};
  std::size_t next_seq = 0;  // only touched by the serial emit node
  // Uncontended locks (the nodes are serial already). They make the order between consecutive
  // emitter (collector) calls on different threads visible to ThreadSanitizer.
  std::mutex emit_mutex;
  std::mutex relay_mutex;
  std::mutex collect_mutex;

  flow::graph graph;
  flow::input_node<int> ticks(graph, [&ended](tbb::flow_control& control) {
    HandoffScope scope;
    if (ended.load(std::memory_order_acquire)) control.stop();
    return 0;
  });
  flow::limiter_node<int, int> limiter(graph, tokens);
  auto give_back_token = [&limiter] { limiter.decrementer().try_put(1); };

  using EmitNode = flow::multifunction_node<int, std::tuple<TaskMsg, std::size_t>>;
  EmitNode emit(graph, flow::serial, [&](int, EmitNode::output_ports_type& ports) {
    HandoffScope scope;
    if (ended.load(std::memory_order_acquire)) {
      give_back_token();
      return;
    }
    std::size_t n = 0;
    std::size_t seq = 0;
    {
      std::lock_guard<std::mutex> lock(emit_mutex);
      std::unique_ptr<FarmItem> item = cb.emit();
      if (!item) {
        ended.store(true, std::memory_order_release);
        give_back_token();
        return;
      }
      seq = next_seq++;
      Slot& slot = slot_of(seq);
      if (!slot.free.load(std::memory_order_acquire)) {
        throw std::logic_error("sg::par farm: slot reused while in flight");
      }
      slot.free.store(false, std::memory_order_relaxed);
      slot.seq = seq;
      slot.item = std::move(item);
      slot.tasks = cb.tasks(*slot.item);
      n = slot.tasks.size();
      slot.remaining.store(n, std::memory_order_relaxed);
      slot.published.store(seq + 1, std::memory_order_release);
    }
    if (n == 0) {
      std::get<1>(ports).try_put(seq);
      return;
    }
    for (std::size_t i = 0; i < n; ++i) std::get<0>(ports).try_put(TaskMsg{seq, i});
  });

  // Port 0: the item's first tasks are done (to the relay, or to the collector without one);
  // port 1: its relay tasks are done (to the collector).
  // A worker that comes free takes the oldest item's task first: a frame's labelling (the relay's
  // tasks) does not wait behind the next frame's stereo and flow tasks that were queued before it,
  // so the frames in flight finish as they arrived instead of all finishing late. The farm
  // rejects what it cannot run at once, and the queue in front of it hands over by priority.
  struct NewerIsLess {
    bool operator()(const TaskMsg& a, const TaskMsg& b) const { return a.seq > b.seq; }
  };
  flow::priority_queue_node<TaskMsg, NewerIsLess> pending(graph);
  using FarmNode =
      flow::multifunction_node<TaskMsg, std::tuple<std::size_t, std::size_t>, flow::rejecting>;
  FarmNode farm(graph, static_cast<std::size_t>(config.workers),
                [&](const TaskMsg& msg, FarmNode::output_ports_type& ports) {
                  HandoffScope scope;
                  Slot& slot = slot_of(msg.seq);
                  // Only the emitter writes `published` (the relay `relayed`), so tasks of one
                  // item are not ordered with each other (for TSan either): they may run at once.
                  (void)slot.published.load(std::memory_order_acquire);
                  if (msg.phase == 1) (void)slot.relayed.load(std::memory_order_acquire);
                  // Isolated so that a worker waiting in a nested parallel_for (tiles, OpenCV)
                  // only helps with its own task instead of picking up another item's task,
                  // which would delay this item behind an unrelated one.
                  tbb::this_task_arena::isolate([&] { slot.tasks[msg.task](); });
                  if (slot.remaining.fetch_sub(1, std::memory_order_release) == 1) {
                    // The last task sees every task's writes before passing the item on.
                    (void)slot.remaining.load(std::memory_order_acquire);
                    if (msg.phase == 0) {
                      std::get<0>(ports).try_put(msg.seq);
                    } else {
                      std::get<1>(ports).try_put(msg.seq);
                    }
                  }
                });

  flow::sequencer_node<std::size_t> sequencer(graph, [](std::size_t seq) { return seq; });
  flow::sequencer_node<std::size_t> relay_sequencer(graph, [](std::size_t seq) { return seq; });

  using RelayNode = flow::multifunction_node<std::size_t, std::tuple<TaskMsg, std::size_t>>;
  RelayNode relay(graph, flow::serial, [&](std::size_t seq, RelayNode::output_ports_type& ports) {
    HandoffScope scope;
    Slot& slot = slot_of(seq);
    (void)slot.published.load(std::memory_order_acquire);
    (void)slot.remaining.load(std::memory_order_acquire);
    std::size_t n = 0;
    {
      std::lock_guard<std::mutex> lock(relay_mutex);
      slot.tasks = cb.relay(*slot.item);
      n = slot.tasks.size();
      slot.remaining.store(n, std::memory_order_relaxed);
      slot.relayed.store(seq + 1, std::memory_order_release);
    }
    if (n == 0) {
      std::get<1>(ports).try_put(seq);
      return;
    }
    for (std::size_t i = 0; i < n; ++i) std::get<0>(ports).try_put(TaskMsg{seq, i, 1});
  });

  flow::function_node<std::size_t, flow::continue_msg> collect(
      graph, flow::serial, [&](std::size_t seq) {
        HandoffScope scope;
        Slot& slot = slot_of(seq);
        (void)slot.published.load(std::memory_order_acquire);  // items without tasks
        (void)slot.remaining.load(std::memory_order_acquire);  // every task's writes
        (void)slot.relayed.load(std::memory_order_acquire);    // items without relay tasks
        {
          std::lock_guard<std::mutex> lock(collect_mutex);
          cb.collect(*slot.item);
          slot.item.reset();
          slot.tasks.clear();  // frees what the tasks captured
        }
        slot.free.store(true, std::memory_order_release);
        give_back_token();
        return flow::continue_msg();
      });

  flow::make_edge(ticks, limiter);
  flow::make_edge(limiter, emit);
  flow::make_edge(flow::output_port<0>(emit), pending);
  flow::make_edge(pending, farm);
  if (cb.relay) {
    // Items without first tasks go through the relay too.
    flow::make_edge(flow::output_port<1>(emit), relay_sequencer);
    flow::make_edge(flow::output_port<0>(farm), relay_sequencer);
    flow::make_edge(relay_sequencer, relay);
    flow::make_edge(flow::output_port<0>(relay), pending);
    flow::make_edge(flow::output_port<1>(relay), sequencer);
    flow::make_edge(flow::output_port<1>(farm), sequencer);
  } else {
    flow::make_edge(flow::output_port<1>(emit), sequencer);
    flow::make_edge(flow::output_port<0>(farm), sequencer);
  }
  flow::make_edge(sequencer, collect);

  handoff_start();
  ticks.activate();
  // Rethrows the first exception of a node body after the graph's context was cancelled: no new
  // node body starts, running ones finish, buffered messages are dropped with the nodes.
  try {
    graph.wait_for_all();
  } catch (...) {
    handoff_join();
    throw;
  }
  handoff_join();
}

}  // namespace

void run_farm(const FarmConfig& config, const FarmCallbacks& callbacks) {
  const std::vector<std::string> problems = validate(config);
  if (!problems.empty()) {
    std::string message = "invalid farm config: ";
    for (std::size_t i = 0; i < problems.size(); ++i) {
      message += (i ? "; " : "") + problems[i];
    }
    throw std::invalid_argument(message);
  }
  if (config.backend == Backend::kSequential) {
    run_sequential(callbacks);
    return;
  }
  run_in_arena(config.threads, [&] { run_graph(config, callbacks); });
}

}  // namespace detail
}  // namespace sg::par
