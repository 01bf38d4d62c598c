"""The committed full-mode tables (``reports/full/NAME.csv``) as the quick report quotes them: one reader for every
section, with the result's provenance state in words."""
from __future__ import annotations

from pathlib import Path

import pandas as pd

from studies import provenance


def full_table(out_dir: Path | None, name: str) -> tuple[pd.DataFrame | None, str]:
    """The committed full-mode table of study ``name`` under ``out_dir/full`` (None where there is none) and its
    provenance state in words (a stale one is quoted as flagged, :mod:`studies.provenance`)."""
    full = Path(out_dir) / "full" if out_dir is not None else None
    if full is None or not (full / f"{name}.csv").is_file():
        return None, ""
    state = provenance.status(full, name)
    return pd.read_csv(full / f"{name}.csv"), (state.state if state.usable else f"**{state.state}**")


def full_rows(out_dir: Path, name: str) -> pd.DataFrame | None:
    """The rows of study ``name``'s committed full-mode table that ran (status ok); None where there is none."""
    df, _ = full_table(out_dir, name)
    return None if df is None else df[df.status == "ok"].reset_index(drop=True)
