#include "sg/par/farm.hpp"

#include <oneapi/tbb/flow_graph.h>
#include <oneapi/tbb/task_arena.h>

#include <atomic>
#include <condition_variable>
#include <cstddef>
#include <deque>
#include <limits>
#include <mutex>
#include <optional>
#include <stdexcept>
#include <thread>
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

void run_sequential(const FarmConfig& config, const FarmCallbacks& cb) {
  while (std::unique_ptr<FarmItem> item = cb.emit()) {
    if (config.not_before) std::this_thread::sleep_until(config.not_before());
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
  bool completed = false;  // all its tasks are done; guarded by the collection lock
  // FarmConfig::not_before, written by the emitter before `published`. Atomic, like the counts:
  // the gate reads it, and ThreadSanitizer cannot see the TBB hand-offs that order that read
  // before the slot's next item is emitted.
  std::atomic<TimePoint> not_before{};
};

using SeqGate = flow::async_node<std::size_t, std::size_t>;

/// Holds the items emitted before their time (FarmConfig::not_before) on a thread of its own and
/// passes each on through the gate when its time comes, in emission order. Held on a worker, an
/// item would leave the items in flight one worker short for the whole wait. Once stopped, what
/// is still held is let go without being passed on (the run failed).
class Holder {
 public:
  explicit Holder(SeqGate::gateway_type& gateway)
      : gateway_(gateway), thread_([this] { loop(); }) {}
  ~Holder() {
    stop();
    thread_.join();
  }
  Holder(const Holder&) = delete;
  Holder& operator=(const Holder&) = delete;

  /// Takes the item unless its time has come and nothing is held before it (false: the caller
  /// passes it on at once). Called in emission order.
  bool hold(std::size_t seq, TimePoint until) {
    {
      std::lock_guard<std::mutex> lock(mutex_);
      if (stopped_) return true;  // the run failed: let go at once
      if (held_.empty() && !passing_ && until <= Clock::now()) return false;
      gateway_.reserve_wait();  // the graph is not idle while the item is held
      held_.push_back({seq, until});
    }
    wake_.notify_all();
    return true;
  }
  void stop() {
    {
      std::lock_guard<std::mutex> lock(mutex_);
      stopped_ = true;
    }
    wake_.notify_all();
  }

 private:
  struct Held {
    std::size_t seq;
    TimePoint until;
  };

  void loop() {
    std::unique_lock<std::mutex> lock(mutex_);
    for (;;) {
      wake_.wait(lock, [this] { return stopped_ || !held_.empty(); });
      if (held_.empty()) return;
      const Held next = held_.front();
      held_.pop_front();
      passing_ = true;  // a later item must not overtake it while the lock is released
      // Woken early only to stop; then the item is let go at once.
      wake_.wait_until(lock, next.until, [this] { return stopped_; });
      if (!stopped_) gateway_.try_put(next.seq);  // under the lock: stop() waits for it
      passing_ = false;
      gateway_.release_wait();
    }
  }

  SeqGate::gateway_type& gateway_;
  std::mutex mutex_;
  std::condition_variable wake_;
  std::deque<Held> held_;
  bool stopped_ = false;
  bool passing_ = false;
  std::thread thread_;  // last: starts once the members it uses exist
};

/// What a message to the farm asks for: a task of an item's first round or of its relay's round,
/// or (just-in-time admission) leave to emit the next item, queued behind every task.
enum Phase : int { kFirstTasks = 0, kRelayTasks = 1, kAdmit = 2 };

struct TaskMsg {
  std::size_t seq = 0;
  std::size_t task = 0;
  int phase = kFirstTasks;
};

/// The leave to emit: the largest sequence number, so that in the farm's queue it comes after
/// every item's tasks.
constexpr TaskMsg kAdmitMsg{std::numeric_limits<std::size_t>::max(), 0, kAdmit};

void run_graph(const FarmConfig& config, const FarmCallbacks& cb) {
  const auto tokens = static_cast<std::size_t>(config.tokens);
  std::vector<Slot> ring(tokens);
  auto slot_of = [&ring, tokens](std::size_t seq) -> Slot& { return ring[seq % tokens]; };
  std::atomic<bool> ended{false};
  std::size_t next_seq = 0;  // under emit_mutex
  // Emissions run on whichever thread has the token (a collection and a just-in-time leave can
  // race), so emit_mutex keeps them one at a time and in order. The relay's node is serial
  // already; its lock makes the order between consecutive relay calls on different threads
  // visible to ThreadSanitizer.
  std::mutex emit_mutex;
  std::mutex relay_mutex;

  flow::graph graph;

  // A worker that comes free takes the oldest item's task first: a frame's labelling (the relay's
  // tasks) does not wait behind the next frame's stereo and flow tasks that were queued before it,
  // so the frames in flight finish as they arrived instead of all finishing late. The farm
  // rejects what it cannot run at once, and the queue in front of it hands over by priority.
  struct NewerIsLess {
    bool operator()(const TaskMsg& a, const TaskMsg& b) const { return a.seq > b.seq; }
  };
  flow::priority_queue_node<TaskMsg, NewerIsLess> pending(graph);

  // Just-in-time admission: items emitted whose first round is not over (their relay has not
  // queued its tasks yet), items emitted and not yet collected, and the leaves to emit waiting
  // until the first is zero and the second below the number of workers.
  std::mutex admit_mutex;
  std::size_t first_round = 0;
  std::size_t in_flight = 0;
  std::size_t parked = 0;
  const auto workers = static_cast<std::size_t>(config.workers);
  auto may_admit = [&] { return first_round == 0 && in_flight < workers; };  // under the lock
  auto admission_after = [&](bool first_round_ended, bool collected) {
    std::size_t release = 0;
    {
      std::lock_guard<std::mutex> lock(admit_mutex);
      first_round -= first_round_ended ? 1 : 0;
      in_flight -= collected ? 1 : 0;
      if (may_admit()) std::swap(release, parked);
    }
    // Back into the queue behind the tasks queued already: taken when a worker has no older work
    // left. Each is checked again (the first may start a new first round).
    for (; release > 0; --release) pending.try_put(kAdmitMsg);
  };
  auto first_round_over = [&] { admission_after(true, false); };

  // Collection, in emission order, by the thread that completes the next item: no collector task
  // waits for a free thread behind the next item's tasks. The lock orders consecutive
  // collections (for ThreadSanitizer too); one thread collects at a time, outside it.
  std::mutex collect_mutex;
  std::size_t next_collect = 0;
  bool collecting = false;
  std::function<void()> give_back_token;  // below: emits the next item, or asks leave to
  auto complete = [&](std::size_t seq) {
    std::unique_lock<std::mutex> lock(collect_mutex);
    slot_of(seq).completed = true;
    while (!collecting && slot_of(next_collect).completed &&
           slot_of(next_collect).seq == next_collect) {
      Slot& slot = slot_of(next_collect);
      slot.completed = false;
      collecting = true;
      lock.unlock();
      (void)slot.published.load(std::memory_order_acquire);  // items without tasks
      (void)slot.remaining.load(std::memory_order_acquire);  // every task's writes
      (void)slot.relayed.load(std::memory_order_acquire);    // items without relay tasks
      try {
        cb.collect(*slot.item);
      } catch (...) {
        lock.lock();
        collecting = false;  // the run stops; nothing is collected after this
        throw;
      }
      slot.item.reset();
      slot.tasks.clear();  // frees what the tasks captured
      slot.free.store(true, std::memory_order_release);
      lock.lock();
      ++next_collect;
      collecting = false;
      lock.unlock();
      admission_after(false, true);
      give_back_token();
      lock.lock();
    }
  };

  // Emits the next item with a token, serially (emit_mutex), on the thread that has the token:
  // the thread that collected an item, the farm task that gave leave just in time, or the emit
  // node for the first tokens. A token used to pass a limiter_node and, whenever just-in-time
  // admission was configured, the farm's queue behind every task queued there, even while
  // admit_just_in_time() answered no: a paced run took its next frame 2.7 ms after the token
  // came back at the median and up to 24 ms (a task later), and lost it when that was past the
  // next capture (docs/performance.md, "A freed token takes the next frame at once").
  flow::receiver<std::size_t>* first_stop = nullptr;  // the gate (paced) or the start
  auto emit_one = [&](bool counted) {
    // `counted`: whoever gave leave counted the item's first round already (so that two leaves
    // cannot both pass before either item exists); otherwise it starts here.
    if (!counted) {
      std::lock_guard<std::mutex> lock(admit_mutex);
      ++first_round;
      ++in_flight;
    }
    // Under the lock, so that the emitter is not called again once it has returned nothing, and
    // the gate (Holder::hold) and the start receive items in emission order.
    std::lock_guard<std::mutex> lock(emit_mutex);
    if (ended.load(std::memory_order_acquire)) {
      admission_after(true, true);  // the stream is over: the token is not given back
      return;
    }
    std::unique_ptr<FarmItem> item = cb.emit();
    if (!item) {
      ended.store(true, std::memory_order_release);
      admission_after(true, true);
      return;
    }
    const std::size_t seq = next_seq++;
    Slot& slot = slot_of(seq);
    if (!slot.free.load(std::memory_order_acquire)) {
      throw std::logic_error("sg::par farm: slot reused while in flight");
    }
    slot.free.store(false, std::memory_order_relaxed);
    slot.seq = seq;
    slot.item = std::move(item);
    slot.tasks = cb.tasks(*slot.item);
    slot.remaining.store(slot.tasks.size(), std::memory_order_relaxed);
    if (config.not_before) slot.not_before.store(config.not_before(), std::memory_order_relaxed);
    slot.published.store(seq + 1, std::memory_order_release);
    first_stop->try_put(seq);  // queues or spawns the node's task; never runs it here
  };
  give_back_token = [&] {
    {
      std::lock_guard<std::mutex> lock(admit_mutex);
      if (config.admit_just_in_time && config.admit_just_in_time()) {
        pending.try_put(kAdmitMsg);  // behind: admitted by the farm when it may (kAdmit)
        return;
      }
      ++first_round;  // the item about to be emitted
      ++in_flight;
    }
    emit_one(true);
  };
  flow::function_node<TaskMsg> emit(graph, flow::serial, [&](const TaskMsg&) {
    HandoffScope scope;
    emit_one(false);
    return flow::continue_msg();
  });

  // An item whose time has not come yet (FarmConfig::not_before) waits in the holder. The gate
  // and the start are serial, so items reach the farm's queue in emission order (an idle worker
  // takes whatever arrives first).
  Holder* holder = nullptr;
  SeqGate gate(graph, flow::serial, [&](std::size_t seq, SeqGate::gateway_type& gateway) {
    HandoffScope scope;
    Slot& slot = slot_of(seq);
    (void)slot.published.load(std::memory_order_acquire);
    if (!holder->hold(seq, slot.not_before.load(std::memory_order_relaxed))) gateway.try_put(seq);
  });
  std::optional<Holder> holding;  // after the gate: its thread stops before the gate goes
  if (config.not_before) holder = &holding.emplace(gate.gateway());

  // Starts an item: its first tasks to the farm (none: on to the relay, or collected).
  using StartNode = flow::multifunction_node<std::size_t, std::tuple<TaskMsg, std::size_t>>;
  auto start_item = [&](std::size_t seq, StartNode::output_ports_type& ports) {
    HandoffScope scope;
    Slot& slot = slot_of(seq);
    // No task of the item has run yet, so `remaining` still counts them all (and, being atomic,
    // is safe to read here; the relay replaces the tasks once they are done).
    const std::size_t n = slot.remaining.load(std::memory_order_acquire);
    if (n == 0) {
      if (cb.relay) {
        std::get<1>(ports).try_put(seq);
      } else {
        first_round_over();
        complete(seq);
      }
      return;
    }
    for (std::size_t i = 0; i < n; ++i) std::get<0>(ports).try_put(TaskMsg{seq, i});
  };
  StartNode start(graph, flow::serial, start_item);

  // Port 0: the item's first tasks are done (to the relay). Items whose last tasks are done are
  // collected here; a leave to emit (just in time) emits here.
  using FarmNode = flow::multifunction_node<TaskMsg, std::tuple<std::size_t>, flow::rejecting>;
  FarmNode farm(graph, static_cast<std::size_t>(config.workers),
                [&](const TaskMsg& msg, FarmNode::output_ports_type& ports) {
                  HandoffScope scope;
                  if (msg.phase == kAdmit) {
                    // Just in time: not while an item in flight is in its first round (its
                    // stereo and flow can use every worker) nor while as many items as workers
                    // are in flight; released when that changes.
                    {
                      std::lock_guard<std::mutex> lock(admit_mutex);
                      if (!may_admit() && config.admit_just_in_time()) {
                        ++parked;
                        return;
                      }
                      ++first_round;  // the item about to be emitted
                      ++in_flight;
                    }
                    emit_one(true);
                    return;
                  }
                  Slot& slot = slot_of(msg.seq);
                  // Only the emitter writes `published` (the relay `relayed`), so tasks of one
                  // item are not ordered with each other (for TSan either): they may run at once.
                  (void)slot.published.load(std::memory_order_acquire);
                  if (msg.phase == kRelayTasks)
                    (void)slot.relayed.load(std::memory_order_acquire);
                  // Isolated so that a worker waiting in a nested parallel_for (tiles, OpenCV)
                  // only helps with its own task instead of picking up another item's task,
                  // which would delay this item behind an unrelated one.
                  tbb::this_task_arena::isolate([&] { slot.tasks[msg.task](); });
                  if (slot.remaining.fetch_sub(1, std::memory_order_release) == 1) {
                    // The last task sees every task's writes before passing the item on.
                    (void)slot.remaining.load(std::memory_order_acquire);
                    if (msg.phase == kFirstTasks && cb.relay) {
                      std::get<0>(ports).try_put(msg.seq);
                    } else {
                      if (msg.phase == kFirstTasks) first_round_over();
                      complete(msg.seq);
                    }
                  }
                });

  flow::sequencer_node<std::size_t> relay_sequencer(graph, [](std::size_t seq) { return seq; });

  using RelayNode = flow::multifunction_node<std::size_t, std::tuple<TaskMsg>>;
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
    for (std::size_t i = 0; i < n; ++i) std::get<0>(ports).try_put(TaskMsg{seq, i, kRelayTasks});
    first_round_over();
    if (n == 0) complete(seq);
  });

  if (holder) {
    first_stop = &gate;
    flow::make_edge(gate, start);
  } else {
    first_stop = &start;
  }
  flow::make_edge(flow::output_port<0>(start), pending);
  flow::make_edge(pending, farm);
  if (cb.relay) {
    // Items without first tasks go through the relay too.
    flow::make_edge(flow::output_port<1>(start), relay_sequencer);
    flow::make_edge(flow::output_port<0>(farm), relay_sequencer);
    flow::make_edge(relay_sequencer, relay);
    flow::make_edge(flow::output_port<0>(relay), pending);
  }

  handoff_start();
  // The first tokens; each later one is given back when its item is collected.
  for (std::size_t t = 0; t < tokens; ++t) {
    if (config.admit_just_in_time) {
      pending.try_put(kAdmitMsg);
    } else {
      emit.try_put(kAdmitMsg);
    }
  }
  // Rethrows the first exception of a node body after the graph's context was cancelled: no new
  // node body starts, running ones finish, buffered messages are dropped with the nodes.
  try {
    graph.wait_for_all();
  } catch (...) {
    if (holder) holder->stop();  // nothing held starts after a failure
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
    run_sequential(config, callbacks);
    return;
  }
  run_in_arena(config.threads, [&] { run_graph(config, callbacks); });
}

}  // namespace detail
}  // namespace sg::par
