"""The problem file's schema (ctmrpim.problem.schema) is what the parser checks against and what the README
documents: the README's reference is the generated one, every key has a meaning, and the defaults shown are the
ones the reader applies."""
from __future__ import annotations

from pathlib import Path

from ctmrpim.problem import schema, settings
from ctmrpim.problem.reader import keys

README = Path(__file__).resolve().parents[2] / "README.md"
START = "<!-- problem-file reference: generated from ctmrpim/problem/schema.py"
END = "<!-- end of the problem-file reference -->"


def test_readme_holds_the_generated_reference() -> None:
    text = README.read_text()
    body = text[text.index(START):text.index(END)].split("\n", 1)[1]
    assert body == schema.reference_markdown(), "regenerate: python -m ctmrpim.problem.schema (between the markers)"


def test_the_parser_checks_the_schemas_keys() -> None:
    for s in schema.SECTIONS:
        assert keys.SECTIONS[s.name] == (None if s.keys is None else {k.name for k in s.keys})
    assert set(keys.SECTIONS) == {s.name for s in schema.SECTIONS}


def test_every_key_is_documented_and_settings_defaults_are_the_dataclasses() -> None:
    for s in schema.SECTIONS:
        for k in s.keys or ():
            assert k.meaning and k.type and k.default, (s.name, k.name)
    loading = {k.name: k for k in schema.section("loading").keys}
    assert loading["steps"].default == str(settings.Loading().steps)
    assert loading["tolerance"].allowed == "in (0, 1)"
    method = {k.name: k for k in schema.section("method").keys}
    assert method["integration"].default.startswith('"ctm-vci" (linear)')
    assert method["alpha"].unit == "d_c"
