// The explicit time step of the CFL condition (2.61) for an elastic body: dynamic relaxation
// (§2.5) is stable below it.
#pragma once

#include "fem/material.hpp"
#include "mesh/mesh.hpp"

namespace snede {

// (2.61): Δt = (2/√3) h/c, c = √((λ+2μ)/ρ) (plane stress: √(E/((1−ν²)ρ))), h the smallest
// element size, taken as the diameter of the smallest inscribed sphere (circle); ∞ without cells.
// A membrane's triangles are measured in their own planes, with the plane-stress speed.
double cfl_time_step(const Mesh& mesh, const Material& material, double density);

}  // namespace snede
