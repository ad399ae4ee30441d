// Exact geometric predicates (CGAL's filtered exact-predicates kernel). Topological
// decisions that hang on a sign — which side of a cutting plane a vertex lies on (§3.2),
// whether an edge is locally Delaunay (§5) — must be exact: rounded determinants can
// return the wrong sign or 0 near degeneracy, and inconsistent signs corrupt the mesh.
// The answer is the exact sign for the given doubles, as if evaluated in rational arithmetic.
#pragma once

namespace snede {

// Points are raw pointers to their coordinates: 2 doubles in the *_2d/in_circle
// functions, 3 doubles in the *_3d/in_sphere functions. Results are +1, -1 or 0.

// Sign of det[b − a, c − a]: +1 counter-clockwise, −1 clockwise, 0 collinear.
int orientation_2d(const double* a, const double* b, const double* c);

// Sign of det[b − a, c − a, d − a] (the signed volume of tetrahedron abcd): +1 when d lies
// on the side of plane abc towards which (b − a) × (c − a) points, 0 coplanar.
int orientation_3d(const double* a, const double* b, const double* c, const double* d);

// Sign of the incircle determinant: for counter-clockwise a, b, c, +1 when d is strictly
// inside their circumcircle, −1 outside, 0 on it. Clockwise a, b, c flip the sign.
int in_circle(const double* a, const double* b, const double* c, const double* d);

// Sign of the insphere determinant: for positively oriented a, b, c, d (orientation_3d
// = +1), +1 when e is strictly inside their circumsphere, −1 outside, 0 on it. Negatively
// oriented a, b, c, d flip the sign.
int in_sphere(const double* a, const double* b, const double* c, const double* d, const double* e);

// Whether three points in 3D lie on one line (e.g. a degenerate triangle of a surface).
bool collinear_3d(const double* a, const double* b, const double* c);

}  // namespace snede
