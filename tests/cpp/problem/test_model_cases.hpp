// The bodies the model tests share: a jittered square (plane stress) and a jittered cube, under
// gravity, neo-Hookean or St Venant-Kirchhoff; constraints the tests know independently of
// problem/constraints (their own projection P and anchors); random states that invert nothing.
#pragma once

#include <cmath>
#include <random>
#include <string>
#include <vector>

#include "core/error.hpp"
#include "core/petsc_util.hpp"
#include "problem/model.hpp"
#include "topology/edit_checks.hpp"
#include "topology/refinement_checks.hpp"

namespace snede::testing {

struct ModelCase {
  int dim;
  bool neo_hookean;  // else St Venant-Kirchhoff
};

inline std::string model_case_name(const ModelCase& c) {
  return std::string(c.dim == 2 ? "square_" : "cube_") + (c.neo_hookean ? "neo_hookean" : "st_venant_kirchhoff");
}

inline const ModelCase model_cases[] = {{2, true}, {2, false}, {3, true}, {3, false}};

// An elastic body on the case's mesh (unit square or cube) and a model of it under gravity.
struct LoadedModel {
  Mesh mesh;
  ElasticBody body;
  Model model;

  explicit LoadedModel(const ModelCase& c, Mesh on)
      : mesh(std::move(on)),
        body(mesh, c.neo_hookean ? Material(NeoHookean(3e3, 0.45)) : Material(StVenantKirchhoff(3e3, 0.3)), 1000.0,
             c.dim == 2 ? 0.01 : 0.0),
        model(body) {
    const std::vector<double> gravity{0.0, -9.81, 0.0};
    model.set_gravity(std::span<const double>(gravity.data(), c.dim));
  }
  explicit LoadedModel(const ModelCase& c)
      : LoadedModel(c, c.dim == 2 ? jittered_square(4, 0.2, 3) : shuffled_jittered_cube(2, 0.2, 5)) {}

  PetscInt n_dofs() const { return model.n_dofs(); }
  VecHandle new_vec() const {
    VecHandle v;
    SNEDE_PETSC(VecDuplicate(model.displacement(), v.out()));
    return v;
  }
};

// Values uniform in ±scale, one per dof.
inline std::vector<double> random_values(PetscInt n, double scale, std::mt19937& random) {
  std::uniform_real_distribution<double> value(-scale, scale);
  std::vector<double> values(static_cast<std::size_t>(n));
  for (double& v : values) v = value(random);
  return values;
}

// The constraints the tests put on a model, as the tests understand them (§3.1, §6.6): the
// vertices on x = 0 fixed at random displacements, those on x = 1 sliding along (1, 2[, 2])/‖·‖
// through where they are; P per vertex (0, t tᵀ or I) and the anchors (I − P) must keep.
struct KnownConstraints {
  int dim = 0;
  std::vector<double> projection;  // dim × dim per vertex, row-major
  std::vector<double> anchor;      // per dof
  std::size_t n_fixed = 0, n_sliding = 0;

  // x ← P x
  std::vector<double> project(const std::vector<double>& x) const {
    std::vector<double> out(x.size(), 0.0);
    for (std::size_t v = 0; v < x.size() / dim; ++v)
      for (int i = 0; i < dim; ++i)
        for (int j = 0; j < dim; ++j) out[v * dim + i] += projection[(v * dim + i) * dim + j] * x[v * dim + j];
    return out;
  }
  // x ← (I − P) x
  std::vector<double> complement(const std::vector<double>& x) const {
    std::vector<double> out = project(x);
    for (std::size_t k = 0; k < x.size(); ++k) out[k] = x[k] - out[k];
    return out;
  }
};

// Sets the model's state to `state`, then constrains it as KnownConstraints describes.
inline KnownConstraints constrain(LoadedModel& m, const std::vector<double>& state, std::mt19937& random) {
  const int d = m.model.dim();
  const VertexId n = m.mesh.n_points();
  KnownConstraints known{d, std::vector<double>(static_cast<std::size_t>(n) * d * d, 0.0), state};
  set_vec_values(m.model.displacement(), state);
  std::vector<double> direction{1.0, 2.0, 2.0};
  direction.resize(d);
  double length = 0;
  for (double t : direction) length += t * t;
  for (double& t : direction) t /= std::sqrt(length);
  std::vector<VertexId> fixed, sliding;
  std::vector<double> values;
  std::uniform_real_distribution<double> value(-0.01, 0.01);
  for (VertexId v = 0; v < n; ++v) {
    double* block = &known.projection[static_cast<std::size_t>(v) * d * d];
    const double x = m.mesh.point(v)[0];
    if (x == 0.0) {
      fixed.push_back(v);
      for (int i = 0; i < d; ++i) values.push_back(known.anchor[v * d + i] = value(random));
    } else if (x == 1.0) {
      sliding.push_back(v);
      for (int i = 0; i < d; ++i)
        for (int j = 0; j < d; ++j) block[i * d + j] = direction[i] * direction[j];
    } else {
      for (int i = 0; i < d; ++i) block[i * d + i] = 1.0;
    }
  }
  m.model.fix(fixed, values);
  m.model.slide(sliding, direction);
  known.n_fixed = fixed.size();
  known.n_sliding = sliding.size();
  return known;
}

// The largest difference of two arrays over the largest entry of the second.
inline double relative_difference(const std::vector<double>& a, const std::vector<double>& b) {
  double difference = 0, largest = 0;
  for (std::size_t k = 0; k < a.size(); ++k) {
    difference = std::max(difference, std::abs(a[k] - b[k]));
    largest = std::max(largest, std::abs(b[k]));
  }
  return difference / largest;
}

}  // namespace snede::testing
