"""The methods that solve a :class:`~ctmrpim.problem.case.Case`, found by name.

A method is a :class:`SolutionMethod` (a name, a solve function, its element types). Methods are
announced by entry points of the group ``ctmrpim.methods`` in their distributions' metadata
(``pyproject.toml``): CTM-RPIM by this package (``ctm-rpim =
"ctmrpim.solvers.meshfree:METHOD"``), the scikit-fem reference by its own (``fem =
"reference_fem.method:METHOD"``); :func:`register` adds one at run time. A method is imported on first
use, so the registry imports no solver and a reference can import the core freely. :func:`solve` looks
the method up and calls it: no chain of ``if``s over method names.
"""
from __future__ import annotations

from dataclasses import dataclass
from importlib.metadata import entry_points
from pathlib import Path
from typing import Any, Callable

from ctmrpim.errors import ProblemError
from ctmrpim.problem.case import Case
from ctmrpim.problem.size_estimate import check_fits
from ctmrpim.result import Result
from ctmrpim.run_options import RunOptions

#: entry-point group that announces the methods (this package's and the references')
GROUP = "ctmrpim.methods"
#: the method this package implements
DEFAULT = "ctm-rpim"


@dataclass(frozen=True)
class SolutionMethod:
    """A registered method: ``solve(case, element, options) -> Result``; ``elements`` the element types
    it offers (the first is the default; empty for a method without elements)."""

    name: str
    solve: Callable[[Case, str | None, RunOptions], Result]
    elements: tuple[str, ...] = ()
    description: str = ""


_REGISTRY: dict[str, SolutionMethod] = {}


def register(method: SolutionMethod) -> None:
    """Make ``method`` available under its name (registering a name again replaces it)."""
    _REGISTRY[method.name] = method


def names() -> list[str]:
    """Every method that can be asked for: registered, or announced by an entry point."""
    return sorted({*_REGISTRY, *(ep.name for ep in entry_points(group=GROUP))})


def get(name: str) -> SolutionMethod:
    """The method called ``name``, imported on first use; a ProblemError for an unknown name."""
    if name not in _REGISTRY:
        for ep in entry_points(group=GROUP, name=name):
            method = ep.load()
            if not (isinstance(method, SolutionMethod) and method.name == name):
                raise TypeError(f"entry point {ep.value!r} of {GROUP} is not the SolutionMethod {name!r}")
            register(method)
    if name not in _REGISTRY:
        raise ProblemError(f"unknown method {name!r}; available: {', '.join(names())}", key="--solver")
    return _REGISTRY[name]


def element_of(method: SolutionMethod, element: str | None) -> str | None:
    """The element a solve with ``method`` uses: ``element``, or the method's default where None; an
    element the method does not offer is refused (CTM-RPIM offers none)."""
    if element is None:
        return method.elements[0] if method.elements else None
    if element not in method.elements:
        offered = f"one of {', '.join(method.elements)}" if method.elements else "none (it has no elements)"
        raise ProblemError(f"method {method.name!r} has no element {element!r}: it takes {offered}", key="--element")
    return element


def solve(case: Case, method: str = DEFAULT, element: str | None = None, *,
          progress: Callable[[Any], None] | None = None, out: Path | None = None, resume: bool = False,
          progress_bar: bool = False) -> Result:
    """Solve ``case`` with ``method`` (``"ctm-rpim"``, or a reference such as ``"fem"`` with its
    ``element``, by default the method's first). ``progress`` gets each strength-reduction level as it
    finishes; an explicit dynamic run writes its time series and checkpoints into ``out`` as it goes
    (a temporary folder if None), continues from the checkpoint there with ``resume``, and shows a
    progress bar with ``progress_bar``. An element the method does not offer is refused."""
    entry = get(method)
    element = element_of(entry, element)
    check_fits(case, method)      # before anything is allocated: a clear refusal, not an allocation error
    options = RunOptions(progress=progress or (lambda level: None), out=out, resume=resume,
                         progress_bar=progress_bar)
    return entry.solve(case, element, options)
