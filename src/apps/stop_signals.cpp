#include "stop_signals.hpp"

#include <signal.h>

#include <cassert>
#include <csignal>

namespace sg::apps {
namespace {

// Written by the handler: a lock-free atomic and a sig_atomic_t are all it may touch.
static_assert(std::atomic<bool>::is_always_lock_free);
std::atomic<bool> g_stop{false};
volatile std::sig_atomic_t g_signal = 0;

constexpr int kSignals[] = {SIGINT, SIGTERM};
struct sigaction g_previous[2];
bool g_installed[2] = {false, false};
bool g_active = false;

extern "C" void on_stop_signal(int sig) {
  if (g_signal == 0) g_signal = sig;
  g_stop.store(true, std::memory_order_relaxed);
}

}  // namespace

StopOnSignals::StopOnSignals() {
  assert(!g_active && "one StopOnSignals at a time");
  g_active = true;
  g_stop.store(false);
  g_signal = 0;
  for (int i = 0; i < 2; ++i) {
    struct sigaction current {};
    sigaction(kSignals[i], nullptr, &current);
    if (current.sa_handler == SIG_IGN) continue;
    struct sigaction action {};
    action.sa_handler = on_stop_signal;
    sigemptyset(&action.sa_mask);
    // The handler runs once; the next signal of the kind takes the default action (ends the
    // process), so a second Ctrl-C stops a run whose last frames take too long.
    action.sa_flags = SA_RESETHAND | SA_RESTART;
    g_installed[i] = sigaction(kSignals[i], &action, &g_previous[i]) == 0;
  }
}

StopOnSignals::~StopOnSignals() {
  for (int i = 0; i < 2; ++i) {
    if (g_installed[i]) sigaction(kSignals[i], &g_previous[i], nullptr);
    g_installed[i] = false;
  }
  g_active = false;
}

const std::atomic<bool>& StopOnSignals::flag() const { return g_stop; }

void StopOnSignals::request() { g_stop.store(true, std::memory_order_relaxed); }

int StopOnSignals::signal() const { return g_signal; }

int StopOnSignals::exit_status() const { return g_signal != 0 ? 128 + g_signal : 0; }

}  // namespace sg::apps
