// Owning handles for PETSc objects (Vec, Mat, KSP, SNES, TS, DM, PetscContainer): the object
// is destroyed when the handle goes, so a constructor or solve that throws halfway releases
// what it made. A destroy that fails cannot throw from a destructor; it is reported on stderr
// and counted (destroy_failures()), never ignored.
#pragma once

#include <petscdm.h>
#include <petscksp.h>
#include <petscsf.h>
#include <petscsnes.h>
#include <petscts.h>

#include <utility>

namespace snede {

// Reports a failed destroy (PETSc's code and the object's type) on stderr and counts it.
void report_destroy_failure(PetscErrorCode code, const char* type) noexcept;
// How many destroys have failed in this process.
long destroy_failures() noexcept;

inline const char* petsc_type_name(Vec*) noexcept { return "Vec"; }
inline const char* petsc_type_name(Mat*) noexcept { return "Mat"; }
inline const char* petsc_type_name(KSP*) noexcept { return "KSP"; }
inline const char* petsc_type_name(SNES*) noexcept { return "SNES"; }
inline const char* petsc_type_name(TS*) noexcept { return "TS"; }
inline const char* petsc_type_name(DM*) noexcept { return "DM"; }
inline const char* petsc_type_name(PetscContainer*) noexcept { return "PetscContainer"; }
inline const char* petsc_type_name(PetscSF*) noexcept { return "PetscSF"; }

template <class Object, PetscErrorCode (*destroy)(Object*)>
class PetscHandle {
 public:
  PetscHandle() = default;
  explicit PetscHandle(Object object) noexcept : object_(object) {}
  ~PetscHandle() { reset(); }
  PetscHandle(const PetscHandle&) = delete;
  PetscHandle& operator=(const PetscHandle&) = delete;
  PetscHandle(PetscHandle&& other) noexcept : object_(std::exchange(other.object_, nullptr)) {}
  PetscHandle& operator=(PetscHandle&& other) noexcept {
    if (this != &other) {
      reset();
      object_ = std::exchange(other.object_, nullptr);
    }
    return *this;
  }

  Object get() const noexcept { return object_; }
  operator Object() const noexcept { return object_; }
  explicit operator bool() const noexcept { return object_ != nullptr; }

  // Where a PETSc constructor writes the new object (VecDuplicate(u, handle.out())); the
  // object held before is destroyed first.
  Object* out() noexcept {
    reset();
    return &object_;
  }
  // The handle's own slot, for code that replaces the object in place through a pointer
  // (the model reissues carried fields after a mesh change); the handle still owns it.
  Object* slot() noexcept { return &object_; }

  void reset() noexcept {
    if (!object_) return;
    const PetscErrorCode code = destroy(&object_);
    if (code) report_destroy_failure(code, petsc_type_name(static_cast<Object*>(nullptr)));
    object_ = nullptr;
  }

 private:
  Object object_ = nullptr;
};

using VecHandle = PetscHandle<Vec, VecDestroy>;
using MatHandle = PetscHandle<Mat, MatDestroy>;
using KspHandle = PetscHandle<KSP, KSPDestroy>;
using SnesHandle = PetscHandle<SNES, SNESDestroy>;
using TsHandle = PetscHandle<TS, TSDestroy>;
using DmHandle = PetscHandle<DM, DMDestroy>;
using ContainerHandle = PetscHandle<PetscContainer, PetscContainerDestroy>;
using SfHandle = PetscHandle<PetscSF, PetscSFDestroy>;

}  // namespace snede
