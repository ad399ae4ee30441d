// What an element loop reports besides its result: the elements it could not evaluate
// honestly, and the flops its kernels cost per element.
#pragma once

#include <array>
#include <cstdint>
#include <stdexcept>
#include <vector>

#include "core/counted.hpp"
#include "fem/tensor.hpp"
#include "mesh/connectivity_watcher.hpp"

namespace snede {

// Which elements could not be evaluated honestly in the last call.
struct EvaluationReport {
  std::vector<ElementId> inverted;       // det F ≤ 0 (a membrane: collapsed to zero area)
  std::vector<ElementId> domain_errors;  // non-finite result (exponential overflow)
};

// An evaluation overflowed (Veronda-Westmann's exponential); the message lists elements.
class DomainError : public std::domain_error {
  using std::domain_error::domain_error;
};
// Throws DomainError naming the elements if report.domain_errors is not empty.
void throw_if_domain_error(const EvaluationReport& report);

// Flops per element per kernel, counted by running the kernels on Counted scalars.
struct KernelFlops {
  std::int64_t energy = 0, force = 0, tangent = 0;
  std::int64_t functions = 0;  // sqrt/exp/log calls in the force kernel (not in the counts)
};

// Differences U and a direction dU to count flops at: generic values (no zero or symmetry
// a kernel could skip work on).
template <int R, int C>
std::array<Gradient<Counted, R, C>, 2> flop_count_differences() {
  std::array<Gradient<Counted, R, C>, 2> UdU;
  for (int i = 0; i < R; ++i)
    for (int j = 0; j < C; ++j) {
      UdU[0](i, j) = Counted(0.01 * (i + 2 * j + 1));
      UdU[1](i, j) = Counted(0.1 * (2 * i + j + 1));
    }
  return UdU;
}

// Runs each kernel (a callable on Counted inputs it holds) once and counts its flops.
template <class Energy, class Force, class Tangent>
KernelFlops count_kernel_flops(Energy&& energy, Force&& force, Tangent&& tangent) {
  auto run = [](auto&& kernel) {
    flop_tally() = {};
    kernel();
    return flop_tally();
  };
  KernelFlops flops;
  flops.energy = run(energy).arithmetic;
  const FlopTally force_tally = run(force);
  flops.force = force_tally.arithmetic;
  flops.functions = force_tally.functions;
  flops.tangent = run(tangent).arithmetic;
  return flops;
}

}  // namespace snede
