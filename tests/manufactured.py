"""A manufactured solution: a smooth, non-polynomial displacement field with its body force, on a plate with a
circular hole and a curved end (a circular arc), Dirichlet on a straight edge and on the hole, the exact
traction on the straight top and bottom edges and on the curved end. Plane stress.

u_x = k sin(2x) cos(1.5y),  u_y = k cos(x) sin(2y)
"""
from __future__ import annotations

from pathlib import Path

from ctmrpim.problem.case import Case
from ctmrpim.problem.reader import parse_case

E, NU, K = 1000.0, 0.3, 1e-3
A = E / (1 - NU**2)
G = E / (2 * (1 + NU))
HOLE = (0.8, 0.5, 0.25)           # centre and radius
END = (2.0, 0.5, 0.4)             # the curved end x >= 2, joined to the right edge at y = 0.1 and 0.9

EXX = f"(2*{K}*cos(2*x)*cos(1.5*y))"
EYY = f"(2*{K}*cos(x)*cos(2*y))"
GXY = f"(-1.5*{K}*sin(2*x)*sin(1.5*y) - {K}*sin(x)*sin(2*y))"
FIELD = {
    "ux": f"{K}*sin(2*x)*cos(1.5*y)", "uy": f"{K}*cos(x)*sin(2*y)",
    "sxx": f"{A}*({EXX} + {NU}*{EYY})", "syy": f"{A}*({EYY} + {NU}*{EXX})", "sxy": f"{G}*{GXY}",
}
# b = -div(sigma), differentiated by hand (the test checks it against central differences)
BODY = {
    "bx": f"-({A}*(-4*{K}*sin(2*x)*cos(1.5*y) - 2*{NU}*{K}*sin(x)*cos(2*y))"
          f" + {G}*(-2.25*{K}*sin(2*x)*cos(1.5*y) - 2*{K}*sin(x)*cos(2*y)))",
    "by": f"-({G}*(-3*{K}*cos(2*x)*sin(1.5*y) - {K}*cos(x)*sin(2*y))"
          f" + {A}*(-4*{K}*cos(x)*sin(2*y) - 3*{NU}*{K}*cos(2*x)*sin(1.5*y)))",
}


def exact_traction(where: str, nx: str | float, ny: str | float, field: dict) -> dict:
    """A ``[[traction]]`` entry: the traction sigma n of ``field`` (stresses as expressions) on the edges ``where``,
    the outward normal (nx, ny) numbers or expressions of x and y."""
    return {"where": where, "tx": f"({nx})*({field['sxx']}) + ({ny})*({field['sxy']})",
            "ty": f"({nx})*({field['sxy']}) + ({ny})*({field['syy']})"}


def manufactured_case(spacing: float, method: dict | None = None) -> Case:
    """The manufactured problem on a node cloud of ``spacing``, with ``method`` settings."""
    hx, hy, hr = HOLE
    ex, ey, er = END
    raw = {"problem": {"name": "manufactured", "plane": "stress"},
           "geometry": {"add": [{"rectangle": [0.0, 0.0, ex, 1.0]}, {"circle": [ex, ey, er]}],
                        "subtract": [{"circle": [hx, hy, hr]}]},
           "nodes": {"spacing": spacing},
           "material": {"model": "linear-elastic", "E": E, "nu": NU},
           "constraint": [{"where": "x == 0", "ux": FIELD["ux"], "uy": FIELD["uy"]},
                          {"where": f"hypot(x - {hx}, y - {hy}) == {hr}", "ux": FIELD["ux"], "uy": FIELD["uy"]}],
           "traction": [exact_traction(f"y == 0 and x <= {ex}", 0, -1, FIELD),
                        exact_traction(f"y == 1 and x <= {ex}", 0, 1, FIELD),
                        exact_traction(f"x == {ex} and abs(y - {ey}) >= {er}", 1, 0, FIELD),
                        exact_traction(f"x >= {ex} and hypot(x - {ex}, y - {ey}) == {er}",
                                       f"(x - {ex})/{er}", f"(y - {ey})/{er}", FIELD)],
           "body-force": dict(BODY), "exact": dict(FIELD), "method": dict(method or {})}
    return parse_case(raw, "manufactured", Path("."))
