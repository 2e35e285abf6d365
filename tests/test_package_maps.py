"""Every package's docstring is its map: each module and sub-package of the package is named there, so that a reader
finds where each paper's equations live from the package alone."""

import ast
from pathlib import Path

import pytest

PACKAGE = Path(__file__).resolve().parents[1] / "src" / "poseintegrity"
PACKAGES = sorted(init.parent for init in PACKAGE.rglob("__init__.py"))


def _members(package: Path) -> list[str]:
    """The names a map must hold: modules as ``name.py``, sub-packages as ``name/``."""
    modules = [f"{path.name}" for path in package.glob("*.py") if path.name not in ("__init__.py", "__main__.py")]
    return sorted(modules + [f"{path.name}/" for path in package.iterdir() if (path / "__init__.py").is_file()])


@pytest.mark.parametrize("package", PACKAGES, ids=[str(p.relative_to(PACKAGE.parent)) for p in PACKAGES])
def test_every_module_is_on_its_package_s_map(package):
    docstring = ast.get_docstring(ast.parse((package / "__init__.py").read_text())) or ""
    missing = [name for name in _members(package) if name not in docstring]
    assert not missing, f"{package / '__init__.py'}: its docstring does not name {missing}"


def test_the_check_sees_a_module_missing_from_a_map(tmp_path):
    (tmp_path / "__init__.py").write_text('"""A map.\n\n    kept.py   named\n"""\n')
    (tmp_path / "kept.py").write_text("")
    (tmp_path / "forgotten.py").write_text("")
    docstring = ast.get_docstring(ast.parse((tmp_path / "__init__.py").read_text()))
    assert [name for name in _members(tmp_path) if name not in docstring] == ["forgotten.py"]
