"""Issue 43: no text from a path or name reaches generated code, and no output
replaces an input.

* Every exporter (C of both kinds of table, GLSL, WGSL, HLSL, Verilog, VHDL,
  and the Gappa proofs) run with output paths holding line breaks, carriage
  returns, ``*/``, ``--``, ``//``, a trailing backslash and the trigraph
  ``??/`` writes code that, comments removed, is exactly the code written for
  a plain name: by the languages' own preprocessors (``gcc -E -dD``,
  ``glslangValidator -E``, ``iverilog -E``) and by a comment stripper of this
  file that ends a line comment at every character some language takes as a
  line break (so it shows more code than any compiler, never less).
* ``-o`` (and ``verify --json``, and each ``--proof`` file) resolving to an
  input of the command, directly, through a symbolic link or a hard link, is
  refused with exit 2 and one line naming the flag; the input is unchanged.
* Proof files are named from the whole output name and written with their
  header all or none.
"""

from __future__ import annotations

import os
import re
import shutil
import subprocess
from dataclasses import astuple
from pathlib import Path

import pytest

from conftest import run_cli

ROOT = Path(__file__).resolve().parents[1]
TABLE = ROOT / "figures" / "coefficients" / "dichotomy_d2.json"
PIECEWISE = ROOT / "tests" / "data" / "piecewise_tables" / "rsqrt_uniform.json"

#: (file name stem, folder) pairs a hostile user may give as ``-o``; a file
#: name cannot hold "/" so "*/" and "//" come through the folder part
HOSTILE = [
    ("e\n#define fma(a,b,c) (c)\n#define Z ", ""),
    ("e\r#define mad(a,b,c) (c)\r#define Z ", ""),
    ("e\r\nfn injected() {}\r\n", ""),
    ("e\nmodule injected; endmodule\n", ""),
    ("e\nsignal injected : bit;\n", ""),
    ("e\\", ""),
    ("e ??", ""),
    ("x", "d*"),                         # the command line holds d*/x...
    ("x", "d\n#define Z 1\n/*"),
    ("x -- y", "d--"),
    ("x", "d\\"),
    ("x\u2028#define Z 1", ""),
]

#: format -> (suffix, extra flags)
FORMATS = {
    "c": (".h", ["--proof"]),
    "glsl": (".glsl", ["--proof"]),
    "wgsl": (".wgsl", ["--proof"]),
    "hlsl": (".hlsl", ["--proof"]),
    "verilog": (".v", ["--in-bits", "10", "--out-bits", "10"]),
    "vhdl": (".vhd", ["--in-bits", "10", "--out-bits", "10"]),
}

_LINE_END = re.compile("[\n\r\v\f\x85\u2028\u2029]")


def strip_comments(text: str, lang: str) -> list[str]:
    """The tokens of ``text`` once comments are removed, as ``lang`` would,
    erring on the side of showing code: a line comment ends at the first of
    any line break of any language; C-family line splices (backslash, or
    the trigraph ``??/``, before a line break) are applied first where the
    language has them."""
    if lang in ("c", "glsl", "hlsl"):
        text = text.replace("??/", "\\")
        text = re.sub(r"\\(\r\n|[\n\r])", "", text)
    out, i, n = [], 0, len(text)
    line_comment = "--" if lang == "vhdl" else "//"
    while i < n:
        if text.startswith(line_comment, i):
            m = _LINE_END.search(text, i)
            i = n if m is None else m.start()
        elif text.startswith("/*", i):  # VHDL-2008 has block comments too
            depth, i = 1, i + 2
            while i < n and depth:
                if text.startswith("*/", i):
                    depth, i = depth - 1, i + 2
                elif lang == "wgsl" and text.startswith("/*", i):
                    depth, i = depth + 1, i + 2
                else:
                    i += 1
            assert depth == 0, "an unterminated block comment"
        else:
            out.append(text[i])
            i += 1
    return "".join(out).split()


def _export(fmt: str, table: Path, out: Path) -> dict[str, str]:
    """Run ``chebnorm export`` into ``out``'s folder (made fresh); returns the
    files written there, proofs named relative to the output name."""
    out.parent.mkdir(parents=True)
    suffix, flags = FORMATS[fmt]
    code, _, err = astuple(run_cli(["export", table, "--format", fmt, "-o", out, *flags]))
    assert code == 0, err
    files = {p.name: p.read_text() for p in out.parent.iterdir()}
    main = files.pop(out.name)
    assert all(name.startswith(out.name + ".") for name in files), sorted(files)
    return {"": main, **{name[len(out.name):]: text for name, text in files.items()}}


def _preprocess(fmt: str, text: str) -> str | None:
    """The language's own preprocessor output of ``text`` (None: no such tool);
    run on a copy with a plain name (iverilog cannot open a name holding a
    line break)."""
    import tempfile

    with tempfile.TemporaryDirectory() as d:
        path = Path(d) / f"x{FORMATS[fmt][0]}"
        path.write_text(text)
        return _run_preprocessor(fmt, path)


def _run_preprocessor(fmt: str, path: Path) -> str | None:
    if fmt == "c" and shutil.which("gcc"):
        cmd = ["gcc", "-std=c99", "-E", "-P", "-dD", "-x", "c", str(path)]
    elif fmt == "glsl" and shutil.which("glslangValidator"):
        cmd = ["glslangValidator", "-E", "-S", "frag", str(path)]
    elif fmt == "verilog" and shutil.which("iverilog"):
        cmd = ["iverilog", "-E", "-o", "/dev/stdout", str(path)]
    else:
        return None
    r = subprocess.run(cmd, capture_output=True, text=True, timeout=120)
    assert r.returncode == 0, r.stderr[-2000:]
    return r.stdout


@pytest.mark.parametrize("fmt", list(FORMATS))
def test_hostile_output_names_add_no_code(tmp_path, fmt):
    suffix = FORMATS[fmt][0]
    tables = [TABLE] + ([PIECEWISE] if fmt == "c" else [])
    for t, table in enumerate(tables):
        plain = tmp_path / f"plain{t}" / f"out{suffix}"
        want = _export(fmt, table, plain)
        want_code = strip_comments(want[""], fmt)
        want_pp = _preprocess(fmt, want[""])
        for k, (stem, folder) in enumerate(HOSTILE):
            out = tmp_path / f"case{t}_{k}" / folder / f"{stem}{suffix}" if folder else \
                tmp_path / f"case{t}_{k}" / f"{stem}{suffix}"
            got = _export(fmt, table, out)
            assert strip_comments(got[""], fmt) == want_code, (fmt, stem, folder)
            # every line is one line: no line break of any language inside a comment
            assert not re.search("[\r\v\f\x85\u2028\u2029]", got[""])
            assert sorted(got) == sorted(want)          # the same proofs, named after the output
            for key in want:
                if key:
                    assert got[key] == want[key]        # the scripts name no path
            if want_pp is not None:
                got_pp = _preprocess(fmt, got[""])
                if fmt == "verilog":                    # ivlpp keeps the comments
                    assert strip_comments(got_pp, fmt) == strip_comments(want_pp, fmt)
                else:
                    assert got_pp == want_pp, (fmt, stem, folder)


def test_the_issue_repro_defines_nothing(tmp_path):
    """The issue's command: the name is in the file only inside comments, and
    the preprocessed shader still multiplies in its Horner steps, exactly as
    the shader exported under a plain name."""
    out = tmp_path / "e\n#define fma(a,b,c) (c)\n#define Z .glsl"
    code, _, err = astuple(run_cli(["export", TABLE, "--format", "glsl", "--proof", "-o", out]))
    assert code == 0, err
    text = out.read_text()
    assert not re.search(r"(?m)^\s*#\s*define\s+(fma|Z)\b", text)
    assert "Proof: e_#define fma(a,b,c) (c)_#define Z .glsl.CHEBNORM_DICHOTOMY_D2_" in text
    plain = tmp_path / "plain.glsl"
    assert run_cli(["export", TABLE, "--format", "glsl", "-o", plain]).code == 0
    pp = _preprocess("glsl", text)
    if pp is not None:
        assert "*(x)" in pp and pp == _preprocess("glsl", plain.read_text())


# -- outputs never replace inputs ---------------------------------------------------

def _refused(result, flag: str) -> None:
    code, out, err = astuple(result)
    assert code == 2, (code, err)
    assert err.count("\n") == 1 and "Traceback" not in err, err
    assert flag in err and "is the input" in err, err


@pytest.mark.parametrize("fmt", ["c", "verilog", "json"])
def test_export_onto_its_input_is_refused(tmp_path, fmt):
    table = tmp_path / "dich.json"
    shutil.copy(TABLE, table)
    before = table.read_bytes()
    link = tmp_path / "link.h"
    link.symlink_to(table)
    hard = tmp_path / "hard.h"
    os.link(table, hard)
    flags = FORMATS.get(fmt, ("", []))[1]
    flags = [f for f in flags if f != "--proof"]
    for out in (table, link, hard, tmp_path / "sub" / ".." / "dich.json"):
        (tmp_path / "sub").mkdir(exist_ok=True)
        _refused(run_cli(["export", table, "--format", fmt, "-o", out, *flags]), "-o")
        assert table.read_bytes() == before
    _refused(run_cli(["export", "dich.json", "--format", fmt, "-o", "./dich.json", *flags],
                     cwd=tmp_path), "-o")
    assert table.read_bytes() == before


def test_a_proof_file_onto_the_input_is_refused(tmp_path):
    table = tmp_path / "o.h.CHEBNORM_DICHOTOMY_D2_EVAL_ERROR_BOUND.gappa"
    shutil.copy(TABLE, table)
    before = table.read_bytes()
    _refused(run_cli(["export", table, "--format", "c", "--proof", "-o", tmp_path / "o.h"]),
             "proof file")
    assert table.read_bytes() == before
    assert sorted(p.name for p in tmp_path.iterdir()) == [table.name]   # nothing written


def test_verify_json_onto_an_input_is_refused(tmp_path):
    table = tmp_path / "dich.json"
    shutil.copy(TABLE, table)
    before = table.read_bytes()
    _refused(run_cli(["verify", table, "--json", table, "--inputs", "16"]), "--json")
    link = tmp_path / "l.json"
    link.symlink_to(table)
    _refused(run_cli(["verify", table, "--json", link, "--inputs", "16"]), "--json")
    assert table.read_bytes() == before
    src = tmp_path / "src.h"
    src.write_text("/* a header */\n")
    _refused(run_cli(["verify", table, "--source", src, "--json", src, "--inputs", "16"]),
             "--json")
    assert src.read_text() == "/* a header */\n"


def test_proof_names_come_from_the_whole_output_name(tmp_path):
    """``-o t.h`` then ``-o t.glsl`` (and ``dich.v1.h`` then ``dich.v2.h``)
    keep each other's proofs; each header names exactly its own."""
    outs = {"c": "t.h", "glsl": "t.glsl"}
    for fmt, name in outs.items():
        code, _, err = astuple(run_cli(["export", TABLE, "--format", fmt, "--proof",
                                        "-o", tmp_path / name]))
        assert code == 0, err
    for v in ("dich.v1.h", "dich.v2.h"):
        code, _, err = astuple(run_cli(["export", TABLE, "--format", "c", "--proof",
                                        "-o", tmp_path / v]))
        assert code == 0, err
    names = sorted(p.name for p in tmp_path.iterdir())
    for out in ("t.h", "t.glsl", "dich.v1.h", "dich.v2.h"):
        text = (tmp_path / out).read_text()
        mine = [n for n in names if n.startswith(out + ".") and n.endswith(".gappa")]
        assert mine
        cited = set(re.findall(r"[\w.]+\.gappa", text))
        assert cited == set(mine), (out, cited, mine)
    # the shader's script proves the float32 constant, the header's the double one:
    # both exist side by side
    shader = tmp_path / "t.glsl.CHEBNORM_DICHOTOMY_D2_EVAL_ERROR_BOUND.gappa"
    header = tmp_path / "t.h.CHEBNORM_DICHOTOMY_D2_EVAL_ERROR_BOUND.gappa"
    assert shader.exists() and header.exists() and shader.read_text() != header.read_text()


def test_header_and_proofs_are_written_all_or_none(tmp_path, monkeypatch):
    import chebnorm.core.files as files

    # a proof destination that cannot be written: nothing is, the header neither
    (tmp_path / "t.h.CHEBNORM_DICHOTOMY_D2_Q_EVAL_ERROR_BOUND.gappa").mkdir()
    code, _, err = astuple(run_cli(["export", TABLE, "--format", "c", "--proof",
                                    "-o", tmp_path / "t.h"]))
    assert code == 2 and err.count("\n") == 1 and "is a directory" in err, err
    assert sorted(p.name for p in tmp_path.iterdir()) == [
        "t.h.CHEBNORM_DICHOTOMY_D2_Q_EVAL_ERROR_BOUND.gappa"]
    # a full disk while writing the third file: no file written, no temporary left
    real, calls = files._stage, []

    def stage(given, target, data):
        calls.append(target)
        if len(calls) == 3:
            raise files._refuse(given, "no space left on the device")
        return real(given, target, data)

    monkeypatch.setattr(files, "_stage", stage)
    out = tmp_path / "full" / "t.h"
    out.parent.mkdir()
    code, _, err = astuple(run_cli(["export", TABLE, "--format", "c", "--proof", "-o", out]))
    assert code == 2 and "no space left" in err and len(calls) == 3, err
    assert list(out.parent.iterdir()) == []


def test_the_comment_stripper_shows_code_after_every_line_break():
    """The oracle itself: text after any line break, a spliced line, or a
    closed block comment is code."""
    for brk in ("\n", "\r", "\r\n", "\v", "\f", "\x85", "\u2028", "\u2029"):
        assert strip_comments(f"// a{brk}#define Z 1", "c") == ["#define", "Z", "1"]
        assert strip_comments(f"-- a{brk}signal s : bit;", "vhdl") == ["signal", "s", ":", "bit;"]
    assert strip_comments("// a \\\n#define Z 1\nint y;", "c") == ["int", "y;"]
    assert strip_comments("// a ??/\n#define Z 1\nint y;", "glsl") == ["int", "y;"]
    assert strip_comments("/* a */ int y; /* b */", "c") == ["int", "y;"]
    assert strip_comments("/* a /* b */ fn f() {} */ fn g() {}", "wgsl") == ["fn", "g()", "{}"]
    assert strip_comments("/* a /* b */ fn f() {} */", "c") == ["fn", "f()", "{}", "*/"]


@pytest.mark.parametrize("table", [TABLE, PIECEWISE], ids=["coefficients", "piecewise"])
def test_hw_verilog_into_the_folder_of_its_input_is_refused(tmp_path, table):
    """``hw verilog T -o DIR``: a file it would write that is the table itself."""
    first = tmp_path / "first"
    code, out, err = astuple(run_cli(["hw", "verilog", table, "--in-bits", "10", "--out-bits",
                                      "10", "-o", first]))
    assert code == 0, err
    names = sorted(p.name for p in first.iterdir())
    victim = tmp_path / "second" / names[0]
    victim.parent.mkdir()
    shutil.copy(table, victim)
    before = victim.read_bytes()
    _refused(run_cli(["hw", "verilog", victim, "--in-bits", "10", "--out-bits", "10",
                      "-o", victim.parent]), "-o")
    assert victim.read_bytes() == before
    assert sorted(p.name for p in victim.parent.iterdir()) == [victim.name]
