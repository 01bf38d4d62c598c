"""The sections and keys a problem file may hold, and the check that it holds no others.

Unknown sections and keys are errors with the closest known name suggested; missing required
sections and keys are named. The sections and keys are the schema's (:mod:`ctmrpim.problem.schema`).
"""
from __future__ import annotations

import difflib
from collections.abc import Iterable

from ctmrpim.errors import ProblemError
from ctmrpim.problem import schema

#: section -> its keys (None: any names), from the schema the reference documentation is generated from
SECTIONS: dict[str, set[str] | None] = {s.name: None if s.keys is None else {k.name for k in s.keys}
                                        for s in schema.SECTIONS}
LIST_SECTIONS = {s.name for s in schema.SECTIONS if s.listed}
REQUIRED = {s.name: [k.name for k in s.keys if k.default == schema.REQUIRED]
            for s in schema.SECTIONS if s.keys and any(k.default == schema.REQUIRED for k in s.keys)}
#: Names people reach for instead of the file's keys, to suggest where difflib finds no close spelling.
SYNONYMS = {"youngs": "E", "young": "E", "youngs_modulus": "E", "young_modulus": "E", "modulus": "E",
            "poisson": "nu", "poissons_ratio": "nu", "poisson_ratio": "nu", "rho": "density"}


def check_keys(raw: dict) -> None:
    """Raise for the first unknown section or key, table of the wrong shape, or missing required key."""
    for section, value in raw.items():
        if section not in SECTIONS:
            raise ProblemError(f"unknown section [{section}]{suggest(section, SECTIONS)}")
        allowed = SECTIONS[section]
        entries = value if section in LIST_SECTIONS else [value]
        if section in LIST_SECTIONS and not isinstance(value, list):
            raise ProblemError(f"write it as [[{section}]] (a list of tables)", key=section)
        for i, entry in enumerate(entries):
            where = f"{section}[{i}]" if section in LIST_SECTIONS else section
            if not isinstance(entry, dict):
                raise ProblemError(f"expected a table, got {entry!r}", key=where)
            if allowed is not None:
                for key in entry:
                    if key not in allowed:
                        raise ProblemError(f"unknown key{suggest(key, allowed)}", key=f"{where}.{key}")
            for key in REQUIRED.get(section, []):
                if key not in entry:
                    raise ProblemError("missing required key", key=f"{where}.{key}")
    for section in ("problem", "geometry", "material"):
        if section not in raw:
            raise ProblemError(f"missing section [{section}]")


def suggest(word: str, options: Iterable[str]) -> str:
    """`` (did you mean 'x'?)`` for the closest option: a known synonym (``youngs`` -> ``E``), a
    different capitalisation (``e`` -> ``E``), or the closest spelling; ``""`` if none is close."""
    options = list(options)
    lower = {o.lower(): o for o in options}
    if SYNONYMS.get(word.lower()) in options:
        close = [SYNONYMS[word.lower()]]
    elif word.lower() in lower:
        close = [lower[word.lower()]]
    else:
        close = difflib.get_close_matches(word, options, n=1)
    return f" (did you mean {close[0]!r}?)" if close else ""
