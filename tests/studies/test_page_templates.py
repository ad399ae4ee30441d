"""The results pages' prose lives in studies/templates/<name>.md (issue 36 item 4): the rules of
PageTemplate, and every template's snippets are used by its generator."""
import re
from pathlib import Path

import pytest

from studies.experiments import common
from studies.experiments.common import PageTemplate

STUDIES = Path(common.__file__).resolve().parents[1]


def test_page_snippets_placeholders_and_paragraphs_left_out(tmp_path, monkeypatch):
    (tmp_path / "page.md").write_text(
        "# Title {value:.2f}\n\n{table}\n\n{optional}\n\nEnd {{braces}}{tail}\n\n\n"
        "<!-- snippet tail -->\n, tail {n}\n\n"
        "<!-- snippet block -->\nFirst.\n\nSecond.\n")
    monkeypatch.setattr(common, "TEMPLATES", tmp_path)
    template = PageTemplate("page")
    assert template.snippets == {"tail": ", tail {n}", "block": "First.\n\nSecond."}
    tail = template.snippet("tail", n=3)
    assert template.page(value=1, table="| a |\n", optional="", tail=tail) == "# Title 1.00\n\n| a |\n\nEnd {braces}, tail 3\n"
    assert template.page(value=1, table="| a |\n", optional=template.snippet("block"), tail="") == \
        "# Title 1.00\n\n| a |\n\nFirst.\n\nSecond.\n\nEnd {braces}\n"
    with pytest.raises(KeyError):
        template.page(value=1, table="")


@pytest.mark.parametrize("path", sorted((STUDIES / "templates").glob("*.md")), ids=lambda path: path.stem)
def test_every_snippet_is_used_by_its_generator(path):
    source = (STUDIES / "experiments" / f"{path.stem}.py").read_text()
    unused = [name for name in PageTemplate(path.stem).snippets if f'"{name}"' not in source]
    assert not unused, f"snippets of {path.name} that {path.stem}.py never names: {unused}"
    assert re.search(rf'PageTemplate\("{path.stem}"\)', source)
