"""The layer rule of docs/ARCHITECTURE.md: ``pipelines`` sits on ``gimbal`` and ``tracker``, which
import neither it nor each other, so that the protocol and the vision side stay usable alone."""
import ast
from pathlib import Path

import pytest

from tests.support import ROOT

FORBIDDEN = {"gimbal": {"pipelines", "tracker"}, "tracker": {"pipelines", "gimbal"}}


def imported_packages(path: Path) -> set[tuple[int, str]]:
    """(line, top-level package) of every absolute import in ``path``, in functions too."""
    found = set()
    for node in ast.walk(ast.parse(path.read_text(), str(path))):
        if isinstance(node, ast.Import):
            found |= {(node.lineno, alias.name.split(".")[0]) for alias in node.names}
        elif isinstance(node, ast.ImportFrom) and node.level == 0 and node.module:
            found.add((node.lineno, node.module.split(".")[0]))
    return found


@pytest.mark.parametrize("package", sorted(FORBIDDEN))
def test_a_lower_package_imports_nothing_above_or_beside_it(package: str) -> None:
    wrong = [f"{path.relative_to(ROOT)}:{line} imports {name}"
             for path in sorted((ROOT / package).rglob("*.py"))
             for line, name in sorted(imported_packages(path)) if name in FORBIDDEN[package]]
    assert not wrong, wrong


def test_the_rule_sees_an_import_inside_a_function(tmp_path: Path) -> None:
    planted = tmp_path / "planted.py"
    planted.write_text("def late():\n    from pipelines.cli import main\n    import tracker.runtime\n")
    assert imported_packages(planted) == {(2, "pipelines"), (3, "tracker")}
