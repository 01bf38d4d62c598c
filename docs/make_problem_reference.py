"""Regenerate the README's problem-file reference from the schema the parser checks against
(ctmrpim/problem/schema.py): ``python docs/make_problem_reference.py``."""
from pathlib import Path

from ctmrpim.problem.schema import update_readme

if __name__ == "__main__":
    update_readme(str(Path(__file__).resolve().parents[1] / "README.md"))
