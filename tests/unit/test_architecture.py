"""The layering rules of docs/architecture.md, checked from the source: every import statement of every
module, inside functions too, and the sizes of modules and functions."""
from __future__ import annotations

import ast
from functools import cache
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[2]
PACKAGES = ("ctmrpim", "reference_fem", "studies")
#: the meshfree method's discretisation and solvers, which the finite-element reference must not use
MESHFREE = ("ctmrpim.discretisation", "ctmrpim.solvers.linear_static", "ctmrpim.solvers.total_lagrangian",
            "ctmrpim.solvers.updated_lagrangian", "ctmrpim.solvers.elastoplastic", "ctmrpim.solvers.meshfree",
            "ctmrpim.solvers.explicit")
MAX_MODULE_LINES = 450
MAX_FUNCTION_LINES = 100


def _name(path: Path) -> str:
    parts = list(path.relative_to(ROOT).with_suffix("").parts)
    return ".".join(parts[:-1] if parts[-1] == "__init__" else parts)


@cache
def modules() -> dict[str, Path]:
    return {_name(f): f for package in PACKAGES for f in sorted((ROOT / package).rglob("*.py"))}


def _within(name: str, prefix: str) -> bool:
    return name == prefix or name.startswith(prefix + ".")


@cache
def imports() -> dict[str, frozenset[str]]:
    """Module -> the modules of the three packages it imports anywhere (resolved to the longest known
    module: ``from ctmrpim.solvers import meshfree`` imports ``ctmrpim.solvers.meshfree``)."""
    known = modules()
    out = {}
    for name, path in known.items():
        package = name if path.name == "__init__.py" else name.rpartition(".")[0]
        found = set()
        for node in ast.walk(ast.parse(path.read_text())):
            if isinstance(node, ast.Import):
                targets = [a.name for a in node.names]
            elif isinstance(node, ast.ImportFrom):
                base = node.module or ""
                if node.level:
                    up = package.split(".")[:len(package.split(".")) - (node.level - 1)]
                    base = ".".join(up + ([node.module] if node.module else []))
                # `from P import m` imports module P.m where there is one, else names of module P
                targets = [f"{base}.{a.name}" if f"{base}.{a.name}" in known else base for a in node.names]
            else:
                continue
            for t in targets:
                while t and t not in known:
                    t = t.rpartition(".")[0]
                if t and t != name:
                    found.add(t)
        out[name] = frozenset(found)
    return out


def reachable(start: str) -> set[str]:
    """Every module ``start`` imports, directly or through others."""
    seen, todo = set(), [start]
    while todo:
        for m in imports()[todo.pop()]:
            if m not in seen:
                seen.add(m)
                todo.append(m)
    return seen


def test_the_import_graph_is_read() -> None:
    assert "ctmrpim.discretisation.rpim" in imports()["ctmrpim.discretisation.configuration"]
    assert "ctmrpim.solvers.linear_static" in imports()["ctmrpim.solvers.meshfree"]   # an import inside a function


def test_no_import_cycle_among_modules() -> None:
    cyclic = sorted(m for m in imports() if m in reachable(m))
    assert not cyclic, f"modules on an import cycle: {cyclic}"


def test_no_import_cycle_among_packages() -> None:
    edges = {(a.split(".")[0], b.split(".")[0]) for a, targets in imports().items() for b in targets}
    assert ("ctmrpim", "reference_fem") not in edges and ("ctmrpim", "studies") not in edges
    assert ("reference_fem", "studies") not in edges


def test_core_imports_no_application_or_command_line() -> None:
    bad = {m: sorted(t for t in targets if _within(t, "studies") or _within(t, "reference_fem")
                     or t == "ctmrpim.cli")
           for m, targets in imports().items() if _within(m, "ctmrpim") and m != "ctmrpim.cli"}
    assert not {m: t for m, t in bad.items() if t}


@pytest.mark.parametrize("layer, forbidden", [
    ("ctmrpim.problem", ("ctmrpim.solvers", "ctmrpim.discretisation", "ctmrpim.methods", "ctmrpim.cli")),
    ("reference_fem", MESHFREE),
])
def test_layer_does_not_reach(layer: str, forbidden: tuple[str, ...]) -> None:
    """Directly or through other modules."""
    bad = {m: sorted(t for t in reachable(m) if any(_within(t, f) for f in forbidden))
           for m in imports() if _within(m, layer)}
    assert not {m: t for m, t in bad.items() if t}


def _sources() -> list[Path]:
    return sorted(f for d in (*PACKAGES, "tests", "performance") for f in (ROOT / d).rglob("*.py"))


def test_no_module_is_too_long() -> None:
    long = {str(f.relative_to(ROOT)): n for f in _sources() if (n := f.read_text().count("\n")) > MAX_MODULE_LINES}
    assert not long


def test_no_function_is_too_long() -> None:
    long = {}
    for f in _sources():
        for node in ast.walk(ast.parse(f.read_text())):
            if isinstance(node, (ast.FunctionDef, ast.AsyncFunctionDef)):
                n = node.end_lineno - node.lineno + 1
                if n > MAX_FUNCTION_LINES:
                    long[f"{f.relative_to(ROOT)}:{node.lineno} {node.name}"] = n
    assert not long
