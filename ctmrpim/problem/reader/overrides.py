"""``--set section.key=value``: settings from the command line applied to a problem file's tables."""
from __future__ import annotations

import copy
import tomllib

from ctmrpim.errors import ProblemError
from ctmrpim.problem.reader.keys import LIST_SECTIONS, SECTIONS

#: the keys of [nodes] that say where the nodes are (exactly one is given)
PLACEMENTS = ("grid", "spacing", "file")


def apply_overrides(raw: dict, overrides: list[str]) -> dict:
    """``section.key=value`` settings (value in TOML syntax, else a string) applied to a raw file."""
    raw = copy.deepcopy(raw)
    for item in overrides:
        dotted, eq, value = item.partition("=")
        section, dot, key = (part.strip() for part in dotted.partition("."))
        if not (eq and dot and section and key):  # `method.=3` would otherwise set a key named ''
            raise ProblemError(f"--set {item!r}: expected section.key=value")
        if section not in SECTIONS or section in LIST_SECTIONS:
            raise ProblemError(f"--set {item!r}: can set keys of {', '.join(s for s in SECTIONS if s not in LIST_SECTIONS)}")
        try:
            parsed = tomllib.loads(f"v = {value}")["v"]
        except tomllib.TOMLDecodeError as exc:
            if value.strip()[:1] in ("[", "{", '"', "'"):  # meant as TOML: a string fallback would hide the typo
                raise ProblemError(f"--set {item!r}: the value is not valid TOML ({exc})") from None
            parsed = value.strip()
        table = raw.setdefault(section, {})
        if section == "parameters" and key not in table:     # it would define a parameter that nothing uses
            known = ", ".join(table) or "none"
            raise ProblemError(f"--set {item!r}: the problem has no parameter {key!r} (its parameters: {known})")
        if section == "nodes" and key in PLACEMENTS:  # grid, spacing and file exclude each other: the new one replaces
            for other in PLACEMENTS:
                table.pop(other, None)
        table[key] = parsed
    return raw
