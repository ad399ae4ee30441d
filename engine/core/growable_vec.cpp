#include "core/growable_vec.hpp"

#include <algorithm>
#include <memory>
#include <utility>

#include "core/error.hpp"
#include "core/petsc_handle.hpp"

namespace snede {
namespace {

// The name under which each Vec holds a reference to the container of its storage.
constexpr const char* storage_key = "snede_growable_storage";

struct Storage {
  PetscScalar* entries = nullptr;
  PetscInt capacity = 0;
  ~Storage() { PetscFree(entries); }
};

PetscErrorCode free_storage(void* pointer) {
  delete static_cast<Storage*>(pointer);
  return 0;
}

// The container of v's storage, or null if v is not growable.
PetscContainer container_of(Vec v) {
  PetscObject container = nullptr;
  SNEDE_PETSC(PetscObjectQuery(reinterpret_cast<PetscObject>(v), storage_key, &container));
  return reinterpret_cast<PetscContainer>(container);
}

Storage& storage_in(PetscContainer container) {
  void* pointer = nullptr;
  SNEDE_PETSC(PetscContainerGetPointer(container, &pointer));
  return *static_cast<Storage*>(pointer);
}

ContainerHandle new_storage(PetscInt capacity) {
  auto storage = std::make_unique<Storage>();
  storage->capacity = capacity;
  SNEDE_PETSC(PetscMalloc1(std::max<PetscInt>(capacity, 1), &storage->entries));
  ContainerHandle container;
  SNEDE_PETSC(PetscContainerCreate(PETSC_COMM_SELF, container.out()));
  SNEDE_PETSC(PetscContainerSetPointer(container, storage.get()));
  SNEDE_PETSC(PetscContainerSetUserDestroy(container, free_storage));
  storage.release();  // the container frees it
  return container;
}

// A Vec of the first n entries of the container's storage; it keeps the container alive.
VecHandle vec_over(PetscContainer container, PetscInt n, PetscInt block_size) {
  VecHandle v;
  SNEDE_PETSC(VecCreateSeqWithArray(PETSC_COMM_SELF, block_size, n, storage_in(container).entries, v.out()));
  SNEDE_PETSC(PetscObjectCompose(reinterpret_cast<PetscObject>(v.get()), storage_key,
                                 reinterpret_cast<PetscObject>(container)));
  return v;
}

void replace(Vec* v, VecHandle& replacement) { std::swap(*v, *replacement.slot()); }  // the handle destroys the old

}  // namespace

void create_growable_vec(PetscInt n, PetscInt block_size, Vec* v) {
  ContainerHandle container = new_storage(n);
  std::fill_n(storage_in(container).entries, n, 0.0);
  VecHandle created = vec_over(container, n, block_size);
  *v = nullptr;
  replace(v, created);
}

void resize_growable_vec(Vec* v, PetscInt n) {
  PetscInt old_n = 0, block_size = 1;
  SNEDE_PETSC(VecGetLocalSize(*v, &old_n));
  SNEDE_PETSC(VecGetBlockSize(*v, &block_size));
  const PetscInt kept = std::min(n, old_n);
  PetscContainer container = container_of(*v);
  ContainerHandle grown;
  if (!container || storage_in(container).capacity < n) {
    const PetscInt capacity = container ? storage_in(container).capacity : old_n;
    grown = new_storage(std::max(n, capacity + capacity / 2));
    const PetscScalar* values = nullptr;
    SNEDE_PETSC(VecGetArrayRead(*v, &values));
    std::copy_n(values, kept, storage_in(grown).entries);
    SNEDE_PETSC(VecRestoreArrayRead(*v, &values));
    container = grown;
  }
  std::fill(storage_in(container).entries + kept, storage_in(container).entries + n, 0.0);
  VecHandle resized = vec_over(container, n, block_size);
  replace(v, resized);
}

PetscInt growable_capacity(Vec v) {
  if (const PetscContainer container = container_of(v)) return storage_in(container).capacity;
  PetscInt n = 0;
  SNEDE_PETSC(VecGetLocalSize(v, &n));
  return n;
}

}  // namespace snede
