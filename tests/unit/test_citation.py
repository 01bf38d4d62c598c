"""CITATION.cff (issue 22, item 8): valid Citation File Format 1.2.0 that names the software at the package's
version and the paper it implements."""
from __future__ import annotations

import re
from pathlib import Path

from ctmrpim.version import __version__

CFF = Path(__file__).resolve().parents[2] / "CITATION.cff"
#: the keys CFF 1.2.0 requires at the top level, and in every entry of ``references``
REQUIRED = ("cff-version", "message", "title", "authors")
REQUIRED_REFERENCE = ("type", "title", "authors")
#: the values of ``type`` the schema allows for the file, and the ones this file may use for a reference
FILE_TYPES = ("software", "dataset")


def _load() -> dict:
    """The file as data: by PyYAML where installed (it comes with dask), else by a reader of the few forms the file
    uses (top-level ``key: value`` and one list of mappings)."""
    text = CFF.read_text()
    try:
        import yaml
    except ImportError:    # pragma: no cover - PyYAML comes with the test extras
        return _minimal(text)
    return yaml.safe_load(text)


def _minimal(text: str) -> dict:
    """Top-level scalars (quoted or not) and the names of top-level lists; enough for the checks below."""
    out: dict = {}
    for line in text.splitlines():
        m = re.match(r"^([A-Za-z-]+):\s*(.*)$", line)
        if m:
            key, value = m.groups()
            out[key] = value.strip().strip('"') if value.strip() not in ("", ">-", "|") else []
    titles = re.findall(r"^  - type: (\S+)\n    title: \"([^\"]+)\"", text, re.M)
    out["references"] = [{"type": t, "title": title, "authors": ["?"]} for t, title in titles]
    return out


def test_citation_file_is_cff_1_2_0() -> None:
    data = _load()
    assert str(data["cff-version"]) == "1.2.0"
    for key in REQUIRED:
        assert data.get(key), f"CITATION.cff lacks {key}"
    assert data.get("type", "software") in FILE_TYPES
    for ref in data["references"]:
        for key in REQUIRED_REFERENCE:
            assert ref.get(key), f"a reference of CITATION.cff lacks {key}"


def test_citation_names_the_package_version_and_the_paper() -> None:
    data = _load()
    assert str(data["version"]) == __version__
    assert "ctmrpim" in data["title"]
    assert any("adaptive CTM-RPIM" in r["title"] for r in data["references"])


def test_minimal_reader_agrees_with_yaml() -> None:
    """The fallback reader gives the same scalars as PyYAML where both run."""
    import pytest
    yaml = pytest.importorskip("yaml")
    full, minimal = yaml.safe_load(CFF.read_text()), _minimal(CFF.read_text())
    for key in ("cff-version", "version", "title", "type"):
        assert str(full[key]) == minimal[key]
    assert [r["title"] for r in full["references"]] == [r["title"] for r in minimal["references"]]
