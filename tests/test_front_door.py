"""The README is a front door (short, its two Quickstart commands first) and the
manual holds no account of how the code was developed."""

import re
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parent.parent
README = (ROOT / "README.md").read_text(encoding="utf-8")

#: phrases that narrate development rather than describe the product: numbered
#: runs, sessions, "before this change", dated accounts, issue numbers as history
NARRATION = [
    r"\bruns? \d+ (to|and) \d+\b", r"\bsession\b", r"\bbefore (this|the) (change|work)",
    r"\bat the start of this work\b", r"\bmeasured on 20\d\d-\d\d-\d\d", r"\bissue[- ]\d+\b",
    r"\bearlier releases?\b", r"\btried and not kept\b", r"\bno longer\b",
    r"\b\d{4}-\d\d-\d\d \((morning|afternoon|evening|later)\)", r"\bin \w+ of \w+ runs\b",
]


def test_readme_is_short_and_starts_with_the_quickstart():
    lines = README.splitlines()
    assert len(lines) <= 300, len(lines)
    head = "\n".join(lines[:40])
    assert ".venv/bin/chebnorm repro" in head
    assert ".venv/bin/python -m pytest -q --full -n auto --dist loadfile" in head


@pytest.mark.parametrize("page", ["README.md"] + sorted(
    str(p.relative_to(ROOT)) for p in (ROOT / "docs").glob("*.md")))
def test_no_development_narration(page):
    text = " ".join((ROOT / page).read_text(encoding="utf-8").split())
    found = [m.group(0) for pattern in NARRATION for m in re.finditer(pattern, text, re.I)]
    assert not found, f"{page}: {found[:5]}"


def test_readme_links_resolve():
    for target in re.findall(r"\]\(((?:docs|figures)/[^)#]+)", README):
        assert (ROOT / target).exists(), target
