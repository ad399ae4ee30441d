"""The README's code, run as written (issue 38, item 9): its statements are what a reader
copies, so they must work as they stand, with what the README says is needed around them."""
import re
from pathlib import Path

import snede

README = Path(__file__).resolve().parents[2] / "README.md"


def inline_code(containing: str) -> list[str]:
    """The README's `inline code` spans that contain ``containing``."""
    return [span for span in re.findall(r"`([^`\n]+)`", README.read_text()) if containing in span]


def test_the_membrane_of_the_readme_is_built_from_boundary_surface_as_written():
    """boundary_surface gives (surface, vertex ids); the README passed that tuple to Body."""
    namespace = {"snede": snede, "box": snede.meshing.box((1.0, 1.0, 1.0), (2, 2, 2)),
                 "material": snede.NeoHookean(E=3e3, nu=0.3)}
    statements = [span for span in inline_code("boundary_surface(box)") if re.match(r"surface\b.*=", span)]
    assert statements, "the README shows boundary_surface(box) without what it returns"
    for statement in statements:
        exec(statement, namespace)
        (body_statement,) = inline_code("snede.Body(surface, material")
        body = eval(body_statement, namespace)
        assert body.mesh.is_surface and body.mesh.n_cells == 48
