// A static solve on a distributed mesh (issue 18): the body's unknowns are a PETSc vector on
// the mesh's communicator, a row block per owned vertex (PETSc's vertex numbering), and every
// rank evaluates the same element kernels (ElasticBody) on its own cells. Each evaluation
// scatters the state to the rank's vertices (owned and ghosts), evaluates locally, and adds
// the ghosts' contributions into their owners (a VecScatter, forward then reverse with
// ADD_VALUES); energies are summed over the ranks. The tangent is a matrix-free MatShell on the
// communicator, so PETSc's SNES and KSP run unchanged on any number of ranks.
//
// Constraints and loads are given by the serial mesh's vertex ids, the same on every rank:
// fixed vertices (all components), their displacements, and nodal forces. A fixed dof's
// residual is u − ū and its tangent row the identity, as in the serial Model.
#pragma once

#include <cstdint>
#include <memory>
#include <span>
#include <string>
#include <vector>

#include "core/petsc_handle.hpp"
#include "fem/elastic_body.hpp"
#include "mesh/distributed_mesh.hpp"
#include "solve/solve_result.hpp"

namespace snede {

struct DistributedConditions {
  std::vector<std::int64_t> fixed;     // serial vertex ids
  std::vector<double> fixed_values;    // dim per fixed vertex
  std::vector<std::int64_t> loaded;    // serial vertex ids
  std::vector<double> forces;          // dim per loaded vertex
};

class DistributedStatic {
 public:
  // Collective. Throws std::invalid_argument (the same on every rank) for conditions of the
  // wrong size or ids outside the serial mesh.
  DistributedStatic(DistributedMesh& part, Material material, double thickness, const DistributedConditions& conditions);
  ~DistributedStatic();
  DistributedStatic(const DistributedStatic&) = delete;
  DistributedStatic& operator=(const DistributedStatic&) = delete;

  // Collective. "cg": one Newton step solved by CG (linear problems); "newton": Newton with
  // CG inside, until ‖F‖ ≤ rtol ‖F(u₀)‖. Preconditioner "none" or "jacobi" (the tangent's
  // diagonal, assembled across the ranks); options under `prefix`.
  SolveResult solve(const std::string& method, const std::string& preconditioner, double rtol, int max_iterations,
                    const std::string& prefix);
  // Π(u) = Π_int(u) − f_extᵀu over the whole body (collective).
  double energy();
  // The displacement of this rank's vertices (owned and ghosts), (n_local_vertices, dim).
  std::vector<double> local_displacement();

  // The SNES callbacks' work.
  void residual(Vec u, Vec F);
  void linearize_at(Vec u);
  void tangent_mult(Vec d, Vec out);
  void tangent_diagonal(Vec diagonal);

 private:
  void to_local(Vec global, std::vector<double>& local);
  void add_to_global(const std::vector<double>& local, Vec global);
  // The fixed owned rows of `out` set to `source`'s entries, or to `value` without a source.
  void set_fixed_rows(Vec out, Vec source, double value);

  DistributedMesh& part_;
  ElasticBody body_;
  int dim_;
  std::vector<std::uint8_t> fixed_local_;   // per local dof
  std::vector<double> fixed_value_local_;   // per local dof
  std::vector<double> load_owned_;          // per owned dof (forces counted once, at the owner)
  std::vector<PetscInt> owned_rows_;        // global row of each owned dof, in local order
  std::vector<PetscInt> owned_local_dof_;   // local dof of each owned dof
  VecHandle u_, work_;
  Vec local_vec_ = nullptr;                 // sequential, all local dofs
  VecScatter scatter_ = nullptr;
  MatHandle tangent_;
  std::vector<double> u_local_, u_linearization_, d_local_, out_local_;
};

}  // namespace snede
