"""The models section: the paper's Figs. 6 and 8 drawn from the benchmark definitions (no case is solved)."""
from __future__ import annotations

from studies import model_figures
from studies.report.markdown import Writer

HEADING = "Models and tracked boundaries (cf. Figs. 6 and 8)"


def write_models(w: Writer) -> None:
    """The section of the alpha shapes of four node clouds (Fig. 6) and the cantilever's two models (Fig. 8), which
    :func:`studies.model_figures.run` draws."""
    w(f"## {HEADING}\n\n{model_figures.__doc__.strip()}\n\n"
      f"![alpha shapes](alpha_shapes.png)\n\n![models](models.png)\n\n")
