#pragma once
/// Independent jobs of uneven length on a few threads: each thread takes the next job index as
/// soon as it is free, so one long job does not hold the others up (the scenes of a suite).
#include <functional>

namespace sg::par {

/// Calls job(i) once for every i in [0, count), on min(count, threads) threads (the caller's
/// among them; threads <= 0: default_threads()), handing out indices in increasing order.
/// After each job that returns, done() is called, never by two threads at once. The first
/// exception a job throws stops the handing out (jobs already started finish) and is rethrown
/// here once every thread has stopped; done() is not called for the failed job.
void for_each_job(int count, int threads, const std::function<void(int)>& job,
                  const std::function<void()>& done = {});

}  // namespace sg::par
