// PETSc log events for the engine's own work, so that -log_view shows where time goes
// (force evaluations, tangent actions) next to PETSc's MatMult and KSPSolve.
#pragma once

#include <petsclog.h>

namespace snede {

// The event `name` in the "snede" class, registered on first use.
PetscLogEvent log_event(const char* name);

// Begins the event on construction and ends it on destruction.
class ScopedEvent {
 public:
  explicit ScopedEvent(PetscLogEvent event) : event_(event) { PetscLogEventBegin(event_, 0, 0, 0, 0); }
  ~ScopedEvent() { PetscLogEventEnd(event_, 0, 0, 0, 0); }
  ScopedEvent(const ScopedEvent&) = delete;
  ScopedEvent& operator=(const ScopedEvent&) = delete;

 private:
  PetscLogEvent event_;
};

}  // namespace snede
