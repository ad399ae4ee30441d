"""snede: soft deformable objects whose meshes change (cuts, bisection, needle insertion).

Importing snede initialises PETSc once, through petsc4py (see ``snede._petsc``).
``snede.output`` (series files, h5py) loads on first use. The applications (scenes, scene
files, the command line, the live window) are ``snede.app``; the library imports neither them
nor pyvista, VTK or matplotlib (the extras ``snede[view]`` and ``snede[plot]``).
"""
import importlib

from snede._petsc import PETSc  # noqa: F401  (initialises PETSc before the engine loads)
from snede._command_line import abort_first_under_mpi4py

abort_first_under_mpi4py()  # after petsc4py's exit handler is registered: see there
from snede._errors import Error  # noqa: F401  (the base of every snede exception)
from snede._snede import (  # noqa: F401
    BodyInUse,
    DomainError,
    EditResult,
    FileError,
    InvalidMesh,
    LinearElastic,
    NeoHookean,
    PetscError,
    StVenantKirchhoff,
    VerondaWestmann,
)
from snede.mesh import Mesh, MeshQuality  # noqa: F401
from snede.body import Body, LockingWarning, formulations  # noqa: F401
from snede._snede import DynamicRelaxationOptions, NeedleOptions, SolveResult, StaticOptions  # noqa: F401
from snede.static import StaticSolver  # noqa: F401
from snede.dynamics import DynamicRelaxation  # noqa: F401
from snede.needle import FrictionProfile, InsertionResult, NeedleInsertion, NeedleStepResult  # noqa: F401
from snede.cutting import TetrahedralCutter, TetrahedralCutterOptions, CutResult  # noqa: F401
from snede.planar_cutting import DelaunayCutter, DelaunayCutterOptions, IncisionLost, PlanarCutResult  # noqa: F401
from snede.surface_cutting import SurfaceCutter, SurfaceCutterOptions  # noqa: F401
from snede.distributed import (DistributedMesh, DistributedRelaxation, DistributedStatic, distribute,  # noqa: F401
                               distribute_cells)
from snede.part_body import PartBody  # noqa: F401
from snede.subdivision_cutting import SubdivisionCutter  # noqa: F401
from snede import _renamed, meshing  # noqa: F401
from snede._output_folder import output_folder  # noqa: F401

__all__ = [
    "Mesh", "MeshQuality", "Body", "meshing", "StaticSolver", "DynamicRelaxation", "SolveResult",
    "StaticOptions", "DynamicRelaxationOptions", "NeedleOptions", "NeedleStepResult", "InsertionResult",
    "FrictionProfile", "NeedleInsertion", "TetrahedralCutter", "TetrahedralCutterOptions", "CutResult", "DelaunayCutter",
    "DelaunayCutterOptions", "PlanarCutResult", "SurfaceCutter", "SurfaceCutterOptions",
    "IncisionLost",
    "SubdivisionCutter", "DistributedMesh", "DistributedRelaxation", "DistributedStatic", "distribute", "distribute_cells",
    "PartBody", "LinearElastic", "StVenantKirchhoff", "NeoHookean", "VerondaWestmann",
    "Error", "BodyInUse", "EditResult", "FileError", "InvalidMesh", "PetscError", "DomainError", "LockingWarning", "formulations", "PETSc",
    "output_folder",
]
__version__ = "0.1.0"

# Submodules that load slow libraries; importing snede does not load them until used.
_ON_FIRST_USE = ("output",)


def __getattr__(name):
    if name in _ON_FIRST_USE:
        return importlib.import_module(f"snede.{name}")
    return _renamed.old_name(__name__, globals(), name)  # CutReport and the other names before issue 51
