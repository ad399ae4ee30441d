"""snede: soft deformable objects whose meshes change (cuts, bisection, needle insertion).

Importing snede initialises PETSc once, through petsc4py (see ``snede._petsc``).
"""
from snede._petsc import PETSc  # noqa: F401  (initialises PETSc before the engine loads)
from snede._snede import InvalidMesh, PetscError  # noqa: F401
from snede.mesh import Mesh, MeshQuality  # noqa: F401
from snede import meshing  # noqa: F401

__all__ = ["Mesh", "MeshQuality", "InvalidMesh", "PetscError", "PETSc", "meshing"]
__version__ = "0.1.0"
