#include "core/log_event.hpp"

#include <map>
#include <string>

#include "core/error.hpp"

namespace snede {

PetscLogEvent log_event(const char* name) {
  static PetscClassId class_id = 0;
  static std::map<std::string, PetscLogEvent> events;
  if (class_id == 0) SNEDE_PETSC(PetscClassIdRegister("snede", &class_id));
  auto it = events.find(name);
  if (it != events.end()) return it->second;
  PetscLogEvent event = 0;
  SNEDE_PETSC(PetscLogEventRegister(name, class_id, &event));
  return events.emplace(name, event).first->second;
}

}  // namespace snede
