// Timing for the C++ benchmarks: the fastest of several calls (one core, a shared machine).
#pragma once

#include <algorithm>
#include <chrono>

namespace snede::benchmarks {

// Seconds of the fastest of `repeats` calls (after one warm-up call).
template <class Work>
double best_seconds(int repeats, Work&& work) {
  work();
  double best = 1e300;
  for (int r = 0; r < repeats; ++r) {
    const auto start = std::chrono::steady_clock::now();
    work();
    best = std::min(best, std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count());
  }
  return best;
}

}  // namespace snede::benchmarks
