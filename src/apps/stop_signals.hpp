#pragma once
/// The clean stop of `run` on SIGINT or SIGTERM (docs/live-and-stop.md): the first signal sets a
/// stop request (pipeline::RunOptions::stop), so the run stops taking frames, finishes those in
/// flight and writes its outputs; a second signal of the same kind ends the process at once (the
/// default action).
#include <atomic>

namespace sg::apps {

/// Installs the handlers for its lifetime and restores the previous ones when destroyed. One at a
/// time per process. A signal ignored when it is constructed (e.g. SIGINT of a background job
/// started by a shell) stays ignored.
class StopOnSignals {
 public:
  StopOnSignals();
  ~StopOnSignals();
  StopOnSignals(const StopOnSignals&) = delete;
  StopOnSignals& operator=(const StopOnSignals&) = delete;

  /// The stop request: true after a signal or request().
  const std::atomic<bool>& flag() const;
  /// Requests the stop without a signal (the live view's q or Esc).
  void request();
  /// The first signal received (SIGINT or SIGTERM), 0 when none.
  int signal() const;
  /// The exit status a run ends with: 128 + signal() (130 for SIGINT, 143 for SIGTERM) after a
  /// signal, else 0.
  int exit_status() const;
};

}  // namespace sg::apps
