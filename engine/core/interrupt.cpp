#include "core/interrupt.hpp"

namespace snede {
namespace {

InterruptCheck installed_check = nullptr;

}  // namespace

void set_interrupt_check(InterruptCheck check) noexcept { installed_check = check; }

void stop_if_interrupted() {
  if (installed_check && installed_check()) throw Interrupted();
}

}  // namespace snede
