"""Issue 51, item 3: one ``snede.Error`` base class for every snede exception, each keeping the
built-in base callers caught before (``except ValueError`` still catches a bad mesh)."""
import numpy as np
import pytest

import snede
from snede import _snede
from snede._petsc import OptionValueError
from snede.mesh_files import DamagedFile
from snede.app._extras import MissingExtra
from snede.app.run_scene import SerialOnly
from snede.app.scene_file import SceneFileError

# each snede exception and the built-in base it had before snede.Error
BUILT_IN_BASES = [
    (snede.InvalidMesh, ValueError),
    (snede.FileError, OSError),
    (snede.DomainError, ArithmeticError),
    (snede.PetscError, RuntimeError),
    (snede.BodyInUse, RuntimeError),
    (snede.IncisionLost, RuntimeError),
    (DamagedFile, ValueError),
    (OptionValueError, ValueError),
    (SceneFileError, ValueError),
    (SerialOnly, NotImplementedError),
    (MissingExtra, ImportError),
]


@pytest.mark.parametrize("error, built_in", BUILT_IN_BASES, ids=lambda x: x.__name__)
def test_each_error_is_a_snede_error_and_keeps_its_built_in_base(error, built_in):
    assert issubclass(error, snede.Error)
    assert issubclass(error, built_in)


def test_the_base_is_one_class_exported_once():
    assert snede.Error is _snede.InvalidMesh.__mro__[1]
    assert "Error" in snede.__all__
    assert issubclass(snede.Error, Exception) and not issubclass(snede.Error, ValueError)


def test_every_exception_snede_exports_derives_from_the_base():
    exported = [getattr(snede, name) for name in snede.__all__]
    errors = [kind for kind in exported if isinstance(kind, type) and issubclass(kind, BaseException)
              and not issubclass(kind, Warning)]
    assert len(errors) >= 7
    assert all(issubclass(kind, snede.Error) for kind in errors), errors


def test_a_bad_mesh_is_caught_as_snede_error_and_as_value_error():
    points = np.array([[0.0, 0.0], [1.0, 0.0], [0.0, 1.0]])
    mesh = snede.Mesh(points, np.array([[0, 1, 2]]))
    mesh.move_vertex(2, point=(0.5, 0.0))  # onto the opposite edge: validate() refuses the flat cell
    with pytest.raises(snede.Error) as caught:
        mesh.validate()
    assert isinstance(caught.value, snede.InvalidMesh)
    with pytest.raises(ValueError):
        mesh.validate()


def test_a_petsc_refusal_is_caught_as_snede_error_and_as_runtime_error():
    snede.PETSc.Options()["snede_test_error_base"] = "not-a-number"
    try:
        with pytest.raises(snede.Error) as caught:
            _snede.option_real("-snede_test_error_base")
        assert isinstance(caught.value, snede.PetscError) and isinstance(caught.value, RuntimeError)
    finally:
        del snede.PETSc.Options()["snede_test_error_base"]


def test_a_scene_file_mistake_is_caught_as_snede_error(tmp_path):
    path = tmp_path / "bad.toml"
    path.write_text('[scene]\nno_such_key = 1\n')
    with pytest.raises(snede.Error) as caught:
        snede.app.scene_file.read(path)
    assert isinstance(caught.value, SceneFileError) and isinstance(caught.value, ValueError)
