// Stopping a long solve when the user asks (Ctrl-C). The engine knows nothing of signals: a
// front end installs a check (the Python bindings: "did Python see a SIGINT?"), and the
// solvers' per-iteration callbacks ask it. A callback that is told to stop throws Interrupted,
// which travels back through PETSc as an error to the caller of the solve.
#pragma once

#include <stdexcept>

namespace snede {

class Interrupted : public std::runtime_error {
 public:
  Interrupted() : std::runtime_error("interrupted") {}
};

// The check: true when the user asked to stop. nullptr (the default) never stops.
using InterruptCheck = bool (*)();
void set_interrupt_check(InterruptCheck check) noexcept;

// Throws Interrupted if the installed check says the user asked to stop.
void stop_if_interrupted();

}  // namespace snede
