"""The runtime dependencies pyproject.toml states are exactly the packages rns_viz imports.

Each third-party module imported anywhere in rns_viz must come from a distribution named directly in
``[project] dependencies`` (not merely pulled in by another one), and each stated dependency must be
imported somewhere. Read from the source with :mod:`ast` and the installed packages' metadata.
"""

from __future__ import annotations

import ast
import importlib.metadata
import re
import sys
import tomllib

from tests.support.repo import REPO

# Imported only when present: the optional native step is a distribution of its own (native/).
OPTIONAL_MODULES = {"rns_viz_native"}
# Modules that run only with an extra installed (jupyter-server-proxy imports rns_viz.jupyter): their imports
# must be stated in that extra instead.
EXTRA_FILES = {"rns_viz/jupyter.py": "jupyter"}


def _normalise(name: str) -> str:
    return re.sub(r"[-_.]+", "-", name).lower()


def _stated(extra: str | None = None) -> set[str]:
    project = tomllib.loads((REPO / "pyproject.toml").read_text())["project"]
    specs = project["dependencies"] if extra is None else project["optional-dependencies"][extra]
    return {_normalise(re.split(r"[\s<>=!~;\[]", spec, maxsplit=1)[0]) for spec in specs}


def _imported_modules(extra: str | None = None) -> dict[str, str]:
    """Top-level third-party module -> one file importing it (the files of ``extra``, or all the others)."""
    found: dict[str, str] = {}
    for path in sorted((REPO / "rns_viz").rglob("*.py")):
        if EXTRA_FILES.get(str(path.relative_to(REPO))) != extra:
            continue
        for node in ast.walk(ast.parse(path.read_text(), str(path))):
            if isinstance(node, ast.Import):
                names = [alias.name for alias in node.names]
            elif isinstance(node, ast.ImportFrom) and node.level == 0 and node.module:
                names = [node.module]
            else:
                continue
            for name in names:
                top = name.split(".")[0]
                if top != "rns_viz" and top not in sys.stdlib_module_names and top not in OPTIONAL_MODULES:
                    found.setdefault(top, str(path.relative_to(REPO)))
    return found


def _top_level_modules(distribution: str) -> set[str]:
    """The importable top-level names a distribution installs (also under a nested site-packages, as
    pinocchio's cmeel wheel puts them)."""
    names = set()
    for file in importlib.metadata.files(distribution) or []:
        parts = file.parts
        if "site-packages" in parts:
            parts = parts[parts.index("site-packages") + 1 :]
        if len(parts) > 1 or file.suffix == ".py":
            names.add(parts[0].removesuffix(".py"))
    return names


def _providers(extra: str | None = None) -> dict[str, set[str]]:
    """Stated dependency -> the top-level modules it installs."""
    return {name: _top_level_modules(name) for name in _stated(extra)}


def test_every_imported_package_is_a_stated_dependency() -> None:
    provided = set().union(*_providers().values())
    unstated = {module: where for module, where in _imported_modules().items() if module not in provided}
    assert not unstated, f"imported but not stated in [project] dependencies: {unstated}"


def test_what_an_extras_module_imports_is_stated_in_that_extra() -> None:
    for extra in sorted(set(EXTRA_FILES.values())):
        provided = set().union(*_providers(extra).values(), *_providers().values())
        unstated = {module: where for module, where in _imported_modules(extra).items() if module not in provided}
        assert not unstated, f"imported but not stated in the {extra} extra: {unstated}"


def test_every_stated_dependency_is_imported() -> None:
    imported = set(_imported_modules())
    unused = {name for name, modules in _providers().items() if not modules & imported}
    assert not unused, f"stated but never imported by rns_viz: {unused}"
