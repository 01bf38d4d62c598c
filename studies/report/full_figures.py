"""The committed full-mode figures of the paper's figures, listed in the quick report beside the quick ones with
the provenance state of each (`python -m studies.provenance reports/full`): what a reader of the paper looks for, at the paper's
resolution, without running the full studies.

The sections of the report that already show a full-mode figure (the tip load and the end moment, the column
collapse's full-mode notes) are not repeated here.
"""
from __future__ import annotations

from pathlib import Path

import pandas as pd

from studies import provenance
from studies.report.markdown import Writer, md

HEADING = "Full-mode figures of the paper's figures (committed)"
#: (study, the paper's figure it draws), in the paper's order; a study without a committed figure is left out.
FIGURES = (
    ("node_density", "Fig. 9: tip deflection and its error against the node count"),
    ("integration_density", "Fig. 10: the integration sub-segments r_x, r_y"),
    ("support_radius", "Fig. 11: the support radius r_c"),
    ("shape_parameter", "Fig. 12: the shape parameter eta"),
    ("slope_srf_sweep", "Fig. 19b: the slope's maximum displacement against the SRF (strength reduction)"),
    ("slope_relaxation", "Fig. 19a and 19b: the slope's maximum displacement at every dynamic-relaxation step for "
                         "each SRF of the full run, and its final value against the SRF"),
    ("slope_stability", "Figs. 18-19: the factor-of-safety brackets of both slopes and the vertical cut on three "
                        "clouds each, against Bishop"),
    ("slope_slide", "Fig. 21: the slope at SRF = 1.6 sliding, on the paper's cloud over the benchmark's duration"),
    ("footing_bearing", "Fig. 24: the footing's settlement against the pressure, the undrained footing on three "
                        "grids and the frictional ones on three clouds"),
)


def committed(out_dir: Path) -> list[tuple[str, str, provenance.Status]]:
    """(study, what it draws, provenance status) of each figure of :data:`FIGURES` committed under ``out_dir/full``."""
    full = Path(out_dir) / "full"
    return [(name, what, provenance.status(full, name)) for name, what in FIGURES
            if (full / f"{name}.png").is_file()]


def write_full_figures(w: Writer, out_dir: Path) -> None:
    """The committed full-mode figures of :data:`FIGURES` under ``out_dir/full``: a table of their provenance states,
    then each figure, its state beside it (a result not current is flagged: drawn by other numerics)."""
    w(f"## {HEADING}\n\n{__doc__.split(chr(10) + chr(10))[0].strip()}\n\n")
    rows = committed(out_dir)
    if not rows:
        w("No full-mode figure is committed under `reports/full/`.\n\n")
        return
    w(md(pd.DataFrame([{"figure": f"`reports/full/{name}.png`", "draws (cf. the paper)": what,
                        "state": s.state if s.usable else f"**{s.state}**"} for name, what, s in rows])) + "\n\n")
    for name, what, s in rows:
        flag = "" if s.usable else " (**not current**: drawn by the code that made it, not by this code's numerics)"
        w(f"**{what}** (`reports/full/{name}.png`, {s.state}{flag}):\n\n"
          f"![{name.replace('_', ' ')}, full mode](full/{name}.png)\n\n")
