"""The Python the user guide shows runs as written and says what its comments say."""

from __future__ import annotations

import re
from pathlib import Path

import pytest

GUIDE = Path(__file__).resolve().parent.parent / "docs" / "guide.md"


def _section(title: str) -> str:
    text = GUIDE.read_text(encoding="utf-8")
    start = text.index(title)
    end = text.find("\n## ", start)
    return text[start:end if end != -1 else None]


@pytest.mark.filterwarnings("ignore::chebnorm.approx.FitWarning")
def test_what_the_fit_sees_for_you_runs():
    import chebnorm as cn
    from chebnorm.approx import fit

    block = re.search(r"```python\n(.*?)```", _section("### What the fit sees for you"), re.S).group(1)
    names = {"cn": cn}
    exec(compile(block, str(GUIDE), "exec"), names)   # the guide's own text, nothing else
    t, s, q, r = names["t"], names["s"], names["odd"], names["r"]
    assert t.degree == 6 and t.abs_error_bound <= 2 ** -24
    assert fit("exp(x)", (0, 1), 5).abs_error_bound > 2 ** -24   # the degree below fails
    assert "degrees tried" in t.provenance["degree_search"]
    assert s.abs_error_bound < 1e-10
    assert all(c == 0.0 for c in q.coefficients[0::2]) and q.coefficients[1] != 0.0
    assert r.basis_choice.basis == "shifted"
