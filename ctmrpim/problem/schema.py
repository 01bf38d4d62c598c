"""The problem file's schema: every section and key with its type, default, allowed values, unit, the analyses
that read it and what it means.

One definition serves the parser and the documentation: the key check of the reader
(:mod:`ctmrpim.problem.reader.keys`: unknown and missing keys) takes its sections, keys and required keys from
here, and the README's problem-file reference is generated from here (``python docs/make_problem_reference.py``
rewrites it; a test compares it with the README), so the two cannot drift. The settings tables
(``[method]``, ``[loading]``, ``[strength-reduction]``, ``[dynamic]``, ``[explicit]``) are read off their
dataclasses (:mod:`ctmrpim.problem.settings`): the default from the field, what is allowed from the rule that
validates it, the meaning from the comment beside the field.
"""
from __future__ import annotations

import inspect
import io
import json
import tokenize
from dataclasses import MISSING, dataclass, fields
from typing import Any, get_type_hints

from ctmrpim.problem import settings as _settings
from ctmrpim.problem.expressions import CONSTANTS, FUNCTIONS

#: units of the settings that have one (lengths of [method] are multiples of the node spacing d_c)
UNITS = {("Method", "support_radius"): "d_c", ("Method", "line_spacing"): "d_c", ("Method", "alpha"): "d_c",
         ("Method", "match_tolerance"): "d_c", ("Explicit", "duration"): "s", ("Explicit", "dt"): "s",
         ("Explicit", "viscosity"): "s", ("Explicit", "save_every"): "s", ("Explicit", "checkpoint_every"): "steps",
         ("Relaxation", "steps"): "steps", ("Relaxation", "record_every"): "steps"}
REQUIRED = "required"
OPTIONAL = "optional"
EXPRESSION = "expression of x, y"
NUMBER = "number or expression"
ALL = "all"
STATIC = "linear, quasi-static, strength-reduction, dynamic"


@dataclass(frozen=True)
class Key:
    """One key: its TOML type, default (``REQUIRED``, ``OPTIONAL`` for absent-means-unused, or the value as
    written), allowed values, unit and meaning."""

    name: str
    type: str
    default: str = OPTIONAL
    allowed: str = ""
    unit: str = ""
    meaning: str = ""


@dataclass(frozen=True)
class Section:
    """One section: ``[name]`` (or ``[[name]]`` where ``listed``), the analyses that read it, its keys (None: any
    names, the parameters) and what it is."""

    name: str
    read_by: str
    keys: tuple[Key, ...] | None
    meaning: str
    listed: bool = False


def _toml(value: Any) -> str:
    """A default as written in a problem file."""
    if isinstance(value, bool):
        return "true" if value else "false"
    if isinstance(value, str):
        return json.dumps(value)
    if isinstance(value, tuple):
        return "[" + ", ".join(_toml(v) for v in value) + "]"
    if isinstance(value, float):
        return f"{value:.6g}"
    return str(value)


def _comments(cls: type) -> dict[str, str]:
    """The comment beside each field of a settings dataclass (and its continuation lines), by field name."""
    out: dict[str, str] = {}
    current = None
    for tok in tokenize.generate_tokens(io.StringIO(inspect.getsource(cls)).readline):
        if tok.type == tokenize.NAME and tok.start[1] == 4 and tok.string in cls.__dataclass_fields__:
            current = tok.string
        elif tok.type == tokenize.NAME and tok.start[1] == 4:
            current = None
        elif tok.type == tokenize.COMMENT and current is not None:
            text = tok.string.lstrip("#").strip()
            out[current] = f"{out[current]} {text}" if current in out else text
    return out


def _settings_keys(cls: type) -> tuple[Key, ...]:
    """The keys of a settings dataclass: default from the field, allowed values from its rule, meaning from the
    comment beside it."""
    instance = cls()
    allowed = {key: why.removeprefix("must ").removeprefix("be ").removeprefix("lie ") for key, _, why in instance.rules()}
    comments = _comments(cls)
    hints = get_type_hints(cls)
    keys = []
    for f in fields(cls):
        default = f.default if f.default is not MISSING else f.default_factory()
        kind = {float: NUMBER, int: "integer", str: "string", bool: "true or false"}.get(hints[f.name], "list")
        if f.name == "dt":
            kind = "number or \"cfl\""
        written = _toml(default)
        if cls is _settings.Method and f.name == "integration":   # its default depends on the analysis
            written = ", ".join(f"{_toml(v)} ({a})" for a, v in _settings.DEFAULT_INTEGRATION.items()) + \
                f", {written} (others)"
        keys.append(Key(f.name, kind, written, allowed.get(f.name, ""), UNITS.get((cls.__name__, f.name), ""),
                        comments.get(f.name, "")))
    return tuple(keys)


SECTIONS: tuple[Section, ...] = (
    Section("problem", ALL, (
        Key("name", "string", REQUIRED, "no / or \\", "", "the problem's name (a benchmark's output folder runs/NAME)"),
        Key("description", "string", OPTIONAL, "", "", "free text, echoed in summary.json"),
        Key("analysis", "string", '"linear"', "linear, quasi-static, strength-reduction, dynamic, explicit", "",
            "what is solved (the analyses are described below)"),
        Key("plane", "string", '"stress"', "stress, strain", "", "plane stress or plane strain (Mohr-Coulomb and "
            "neo-Hookean: strain)"),
        Key("thickness", NUMBER, "1", "> 0", "length", "out-of-plane thickness"),
        Key("gravity", "[gx, gy]", "[0, 0]", "", "length / time^2", "acceleration; the body force is "
            "material.density x gravity (linear and Mohr-Coulomb analyses)"),
    ), "what is solved"),
    Section("parameters", ALL, None, "names for numbers, each a number or an expression of the earlier ones, usable "
            f"in every expression; not x, y, t, the constants ({', '.join(CONSTANTS)}) or a function's name"),
    Section("geometry", ALL, (
        Key("add", "list of shapes", REQUIRED, "rectangle = [x0, y0, x1, y1], polygon = [[x, y], ...], "
            "circle = [x, y, r]", "length", "the regions whose union is the body"),
        Key("subtract", "list of shapes", "[]", "as add", "length", "regions removed from it (holes, notches)"),
    ), "the body"),
    Section("nodes", ALL, (
        Key("grid", "[nx, ny]", OPTIONAL, "integers >= 2", "", "a tensor grid over the bounding box, nodes outside "
            "the body dropped; exactly one of grid, spacing and file"),
        Key("spacing", NUMBER, OPTIONAL, "> 0", "length", "a square grid of this spacing"),
        Key("file", "string", OPTIONAL, "a CSV file with a header row and columns x, y", "",
            "node positions; the path is relative to the problem file"),
        Key("jitter", NUMBER, "0", "0 to 0.4", "spacing", "moves every generated node off the boundary by a "
            "random offset of up to this fraction of the spacing along each axis (an irregular cloud)"),
        Key("seed", "integer", "0", ">= 0", "", "the random generator's seed of jitter (only with jitter)"),
    ), "the field nodes"),
    Section("material", ALL, (
        Key("model", "string", REQUIRED, "linear-elastic, neo-hookean, mohr-coulomb", "",
            "linear analyses: linear-elastic; quasi-static: any; the others: mohr-coulomb"),
        Key("E", NUMBER, REQUIRED, "> 0", "stress", "Young's modulus"),
        Key("nu", NUMBER, REQUIRED, "(-1, 0.5)", "", "Poisson's ratio"),
        Key("density", NUMBER, "0", ">= 0", "mass / volume", "gravity acts through it; the mass of explicit "
            "dynamics (0 with gravity is refused)"),
        Key("c", NUMBER, OPTIONAL, ">= 0", "stress", "Mohr-Coulomb cohesion (required there, refused elsewhere)"),
        Key("phi", NUMBER, OPTIONAL, "[0, 90)", "degrees", "Mohr-Coulomb friction angle (required there)"),
        Key("psi", NUMBER, "0", "[0, phi]", "degrees", "Mohr-Coulomb dilation angle"),
        Key("tension", NUMBER, OPTIONAL, ">= 0", "stress", "Mohr-Coulomb tension cut-off on the largest principal "
            "stress"),
    ), "the constitutive model"),
    Section("method", ALL, _settings_keys(_settings.Method), "CTM-RPIM's settings (lengths as multiples of the "
            "mean node spacing d_c, Eq. 36); the finite-element reference reads match_tolerance only"),
    Section("loading", "quasi-static, strength-reduction", _settings_keys(_settings.Loading), "load stepping"),
    Section("strength-reduction", "strength-reduction", _settings_keys(_settings.StrengthReduction),
            "the factor-of-safety search (Eqs. 38-39)"),
    Section("dynamic", "dynamic; strength-reduction with solver = \"dynamic-relaxation\"",
            _settings_keys(_settings.Relaxation), "dynamic relaxation"),
    Section("explicit", "explicit", _settings_keys(_settings.Explicit), "explicit dynamics"),
    Section("constraint", STATIC + "; explicit (values 0)", (
        Key("where", EXPRESSION, REQUIRED, "a condition; == matches within method.match_tolerance", "",
            "the boundary nodes it holds"),
        Key("ux", EXPRESSION, OPTIONAL, "finite", "length", "prescribed x displacement"),
        Key("uy", EXPRESSION, OPTIONAL, "finite", "length", "prescribed y displacement (give ux, uy or both)"),
    ), "prescribed displacements; together they must stop every rigid-body motion of a static body", listed=True),
    Section("traction", STATIC, (
        Key("where", EXPRESSION, REQUIRED, "a condition on both ends of a boundary segment", "",
            "the boundary segments it loads"),
        Key("tx", EXPRESSION, OPTIONAL, "finite", "force / area", "x component"),
        Key("ty", EXPRESSION, OPTIONAL, "finite", "force / area", "y component (give tx, ty or both)"),
        Key("follower", "true, false or \"face\"", "false", "true (= \"segment\"), \"face\"", "",
            "quasi-static large deformation: the load turns with its segment or face"),
    ), "surface loads (scaled by the load factor)", listed=True),
    Section("pressure", STATIC, (
        Key("where", EXPRESSION, REQUIRED, "as traction", "", "the boundary segments it loads"),
        Key("p", EXPRESSION, REQUIRED, "finite", "force / area", "normal pressure, positive pushing into the body"),
    ), "normal surface loads", listed=True),
    Section("point_load", STATIC, (
        Key("at", "[x, y]", REQUIRED, "inside the body", "length", "where it acts"),
        Key("fx", NUMBER, "0", "", "force / thickness", "x component"),
        Key("fy", NUMBER, "0", "", "force / thickness", "y component (give fx, fy or both)"),
    ), "concentrated forces (CTM-RPIM)", listed=True),
    Section("probe", ALL, (
        Key("name", "string", REQUIRED, "unique", "", "reported by this name"),
        Key("at", "[x, y]", REQUIRED, "inside the body", "length", "a material point: its displacement and stress "
            "are reported (and compared with [exact])"),
    ), "named points reported in summary.json", listed=True),
    Section("wall", "explicit", (
        Key("name", "string", REQUIRED, "", "", "reported by this name"),
        Key("point", "[x, y]", REQUIRED, "no node behind it", "length", "a point on the wall"),
        Key("normal", "[nx, ny]", REQUIRED, "non-zero", "", "into the body's side"),
        Key("friction", "\"no-slip\" or number", '"no-slip"', ">= 0", "", "no-slip, or a Coulomb coefficient "
            "(0: frictionless)"),
        Key("gate", "true or false", "false", "", "", "holds the body in the gravity stage, removed at t = 0"),
    ), "rigid walls of explicit dynamics", listed=True),
    Section("exact", "linear (warned elsewhere)", (
        Key("ux", EXPRESSION, OPTIONAL, "with uy", "length", "exact x displacement (L2 error, probes)"),
        Key("uy", EXPRESSION, OPTIONAL, "with ux", "length", "exact y displacement"),
        Key("sxx", EXPRESSION, OPTIONAL, "with syy, sxy", "stress", "exact x normal stress (the three: "
            "energy-norm error)"),
        Key("syy", EXPRESSION, OPTIONAL, "with sxx, sxy", "stress", "exact y normal stress"),
        Key("sxy", EXPRESSION, OPTIONAL, "with sxx, syy", "stress", "exact shear stress"),
    ), "an analytical solution: relative L2 and energy-norm errors and probe errors"),
    Section("body-force", "linear", (
        Key("bx", EXPRESSION, "0", "finite", "force / volume", "x component"),
        Key("by", EXPRESSION, "0", "finite", "force / volume", "y component"),
    ), "a body force varying in space (manufactured solutions), besides gravity"),
)


def section(name: str) -> Section:
    """The section called ``name``."""
    return next(s for s in SECTIONS if s.name == name)


def reference_markdown() -> str:
    """The problem-file reference: one table per section (the README holds it, between its markers)."""
    out = []
    for s in SECTIONS:
        head = f"[[{s.name}]]" if s.listed else f"[{s.name}]"
        out.append(f"**`{head}`** {s.meaning}. Read by: {s.read_by}.\n")
        if s.keys is None:
            out.append("\n")
            continue
        out.append("\n| key | type | default | allowed | unit | meaning |\n|---|---|---|---|---|---|\n")
        for k in s.keys:
            cells = [f"`{k.name}`", k.type, f"`{k.default}`" if k.default not in (REQUIRED, OPTIONAL) else k.default,
                     k.allowed, k.unit, k.meaning]
            out.append("| " + " | ".join(c.replace("|", "\\|") for c in cells) + " |\n")
        out.append("\n")
    out.append(f"Expressions may use x, y, the parameters, the constants "
               f"{', '.join(CONSTANTS)} and the functions {', '.join(sorted(FUNCTIONS))}; conditions compare with ==, <, "
               "<=, >, >= and combine with and, or.\n")
    return "".join(out)


#: the README's markers around the generated reference
START = ("<!-- problem-file reference: generated from ctmrpim/problem/schema.py by "
         "`python docs/make_problem_reference.py`; do not edit by hand (a test compares) -->\n")
END = "<!-- end of the problem-file reference -->\n"


def update_readme(path: str) -> None:
    """Rewrite the reference between the markers of the README at ``path`` (atomically)."""
    from pathlib import Path

    from ctmrpim.io.atomic import atomic_write_text

    text = Path(path).read_text()
    head, rest = text.split(START.split(" by ")[0], 1)
    tail = rest.split(END, 1)[1]
    atomic_write_text(Path(path), head + START + reference_markdown() + END + tail)


if __name__ == "__main__":
    print(reference_markdown(), end="")
