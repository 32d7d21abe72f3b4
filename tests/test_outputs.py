"""Every file chebnorm writes goes through the one atomic writer (mode 0644,
the format its name asks for), an unwritable destination is one clear line
naming it, and mesh files keep their own normals and refuse broken numbers."""

from __future__ import annotations

import io
import os
import stat

import numpy as np
import pytest
from PIL import Image

from chebnorm.core.files import WriteError, make_folder, write_atomic
from chebnorm.raster import IMAGE_FORMATS, get_mesh, load_mesh, write_image, write_png
from conftest import run_cli
from quiet_cli import run_cli_quiet as cli


def _mode(path):
    return stat.S_IMODE(os.stat(path).st_mode)


class TestWriteAtomic:
    def test_mode_and_content(self, tmp_path):
        write_atomic(tmp_path / "a.bin", b"\x00\x01")
        write_atomic(tmp_path / "a.txt", "x\n")
        assert (tmp_path / "a.bin").read_bytes() == b"\x00\x01"
        assert (tmp_path / "a.txt").read_bytes() == b"x\n"
        assert _mode(tmp_path / "a.bin") == _mode(tmp_path / "a.txt") == 0o644

    @pytest.mark.parametrize("dest,reason", [
        ("DIR", "it is a directory"),
        ("DIR/missing/x.txt", "does not exist"),
        ("FILE/x.txt", "is not a folder"),
        ("/proc", "it is a directory"),
        ("/proc/x.txt", "cannot create a file in folder '/proc'"),
    ])
    def test_refusals_name_the_destination(self, tmp_path, dest, reason):
        (tmp_path / "f").write_text("keep")
        dest = dest.replace("DIR", str(tmp_path)).replace("FILE", str(tmp_path / "f"))
        with pytest.raises(WriteError) as info:
            write_atomic(dest, "x")
        msg = str(info.value)
        assert msg.startswith(f"cannot write {dest!r}") and reason in msg
        assert ".tmp" not in msg and "Errno" not in msg
        assert isinstance(info.value, OSError) and isinstance(info.value, ValueError)
        assert sorted(p.name for p in tmp_path.iterdir()) == ["f"]  # no temporary left

    @pytest.mark.skipif(os.geteuid() == 0, reason="root writes into read-only folders")
    def test_read_only_folder(self, tmp_path):
        ro = tmp_path / "ro"
        ro.mkdir()
        ro.chmod(0o555)
        try:
            with pytest.raises(WriteError, match="permission denied"):
                write_atomic(ro / "x.txt", "x")
        finally:
            ro.chmod(0o755)

    def test_make_folder(self, tmp_path):
        assert make_folder(tmp_path / "a" / "b").is_dir()
        (tmp_path / "f").write_text("x")
        with pytest.raises(WriteError, match="exists and is not a folder"):
            make_folder(tmp_path / "f")
        with pytest.raises(WriteError, match="cannot create folder '/proc/chebnorm-x'"):
            make_folder("/proc/chebnorm-x")


class TestImages:
    IMG = np.arange(6 * 5 * 3, dtype=np.uint8).reshape(6, 5, 3)

    @pytest.mark.parametrize("ext", sorted(IMAGE_FORMATS))
    def test_format_follows_extension(self, tmp_path, ext):
        p = tmp_path / f"im{ext}"
        write_image(p, self.IMG)
        assert _mode(p) == 0o644
        with Image.open(p) as im:  # Pillow identifies the format from the bytes
            assert im.format == IMAGE_FORMATS[ext]
            back = np.asarray(im.convert("RGB"))
        if IMAGE_FORMATS[ext] != "JPEG":  # lossless formats give the array back
            np.testing.assert_array_equal(back, self.IMG)
        first = p.read_bytes()
        write_image(p, self.IMG)
        assert p.read_bytes() == first  # deterministic

    def test_unknown_extension_refused(self, tmp_path):
        for name in ("x.gif", "x", "x.png.txt"):
            with pytest.raises(ValueError, match=r"accepted: \.png, \.jpg"):
                write_image(tmp_path / name, self.IMG)
        with pytest.raises(ValueError, match="names another format"):
            write_png(tmp_path / "x.jpg", self.IMG)
        assert list(tmp_path.iterdir()) == []

    def test_render_cli_outputs(self, tmp_path):
        # stderr not read: numba may announce a slow warm-up (NumbaCompileWarning)
        r = run_cli("render", "--mesh", "sphere", "--tess", "6", "--size", "48", "48",
                    "--out", "a.jpg", "--error-map", "e.png", cwd=tmp_path)
        assert r.code == 0, r.err
        for name, fmt in (("a.jpg", "JPEG"), ("e.png", "PNG")):
            assert _mode(tmp_path / name) == 0o644
            with Image.open(tmp_path / name) as im:
                assert im.format == fmt
        for bad in (["--out", "a.gif"], ["--error-map", "e.svg"], ["--out", "/proc"]):
            r = cli("render", "--mesh", "sphere", "--tess", "6", "--size", "48", "48", *bad,
                    cwd=tmp_path)
            assert r.code == 2 and r.err.count("\n") == 1, r.err
            assert bad[0] in r.err and "accepted: .png" in r.err

    @pytest.mark.parametrize("dest", ["/proc", "/proc/x.png", "/sys/x.png"])
    def test_render_unwritable(self, tmp_path, dest):
        r = cli("render", "--mesh", "square", "--tess", "2", "--size", "16", "16",
                "--out", dest, cwd=tmp_path)
        assert r.code == 2 and r.err.count("\n") == 1, r.err
        assert repr(dest) in r.err and ".tmp" not in r.err and "Errno" not in r.err


def test_fit_and_hw_unwritable(tmp_path):
    r = cli("fit", "1/sqrt(x)", "--interval", "1", "2", "--degree", "2", "-o", "/proc",
            cwd=tmp_path)
    assert r.code == 2 and r.err == "chebnorm: error: cannot write '/proc': it is a directory\n"
    r = cli("fit", "1/sqrt(x)", "--interval", "1", "2", "--degree", "2", "--coef-frac-bits", "12", "-o", "t.json",
            cwd=tmp_path)
    assert r.code == 0 and _mode(tmp_path / "t.json") == 0o644
    for dest in ("/proc", "/proc/sub"):
        r = cli("hw", "verilog", "t.json", "--in-bits", "8", "--out-bits", "8", "-o", dest,
                cwd=tmp_path)
        assert r.code == 2 and r.err.count("\n") == 1, r.err
        assert repr(dest) in r.err or "'/proc/" in r.err
        assert "Errno" not in r.err and ".tmp" not in r.err


# --- mesh files ---------------------------------------------------------------------------

#: a flat unit square in z = 0 whose vn are deliberately *not* the face normal
#: (0, 0, 1): trimesh's recomputed normals would all be (0, 0, 1)
TILTED_OBJ = """\
v 0 0 0
v 1 0 0
v 0 1 0
v 1 1 0
vn 3 0 4
vn 0 3 4
vn 0 0 1
vn 0.6 0.8 0.5
f 1//1 2//2 3//3
f 2//2 4//4 3//3
"""


def _write(tmp_path, name, text):
    p = tmp_path / name
    p.write_text(text)
    return p


class TestMeshFiles:
    def test_obj_vn_normals_are_used(self, tmp_path):
        m = load_mesh(_write(tmp_path, "t.obj", TILTED_OBJ))
        want = {(0, 0, 0): (0.6, 0, 0.8), (1, 0, 0): (0, 0.6, 0.8), (0, 1, 0): (0, 0, 1),
                (1, 1, 0): np.array([0.6, 0.8, 0.5]) / np.linalg.norm([0.6, 0.8, 0.5])}
        assert len(m.positions) == 4
        for p, n in zip(m.positions, m.normals):
            np.testing.assert_allclose(n, want[tuple(p)], rtol=0, atol=4 * np.finfo(float).eps)
        # an explicit crease angle recomputes them from the faces: the flat square's +z
        m2 = load_mesh(tmp_path / "t.obj", np.radians(30))
        np.testing.assert_allclose(m2.normals, np.tile([0.0, 0.0, 1.0], (len(m2.normals), 1)),
                                   rtol=0, atol=4 * np.finfo(float).eps)

    def test_vertex_with_two_normals_is_split(self, tmp_path):
        text = "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 1 1 0\nvn 0 0 1\nvn 0 0.6 0.8\n" \
               "f 1//1 2//1 3//1\nf 2//2 4//2 3//2\n"
        m = load_mesh(_write(tmp_path, "s.obj", text))
        normals_at = {}
        for p, n in zip(m.positions, m.normals):
            normals_at.setdefault(tuple(p), set()).add(tuple(np.round(n, 12)))
        assert normals_at[(1.0, 0.0, 0.0)] == {(0.0, 0.0, 1.0), (0.0, 0.6, 0.8)}
        assert len(m.faces) == 2

    def test_obj_without_vn_uses_crease(self, tmp_path):
        m = load_mesh(_write(tmp_path, "c.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n"))
        np.testing.assert_allclose(m.normals, [[0, 0, 1]] * 3, atol=1e-15)

    @pytest.mark.parametrize("line,what", [
        ("v nan 1 0", "vertex 4 (line 4) is not finite"),
        ("v 1 inf 0", "vertex 4 (line 4) is not finite"),
        ("v 1 -inf 0", "vertex 4 (line 4) is not finite"),
    ])
    def test_nonfinite_vertex_refused(self, tmp_path, line, what):
        p = _write(tmp_path, "n.obj", f"v 0 0 0\nv 1 0 0\nv 0 1 0\n{line}\nf 1 2 3\nf 2 4 3\n")
        with pytest.raises(ValueError, match=what.replace("(", r"\(").replace(")", r"\)")):
            load_mesh(p)

    @pytest.mark.parametrize("vn,what", [("vn 0 nan 1", "not finite"), ("vn 0 0 0", "zero vector")])
    def test_bad_normal_refused(self, tmp_path, vn, what):
        p = _write(tmp_path, "b.obj", f"v 0 0 0\nv 1 0 0\nv 0 1 0\nvn 0 0 1\n{vn}\n"
                   "f 1//1 2//1 3//2\n")
        with pytest.raises(ValueError, match=rf"normal 2 \(line 5\) .*{what}"):
            load_mesh(p)

    def test_nonfinite_ply_vertex_refused(self, tmp_path):
        p = _write(tmp_path, "n.ply", "ply\nformat ascii 1.0\nelement vertex 4\nproperty float x\n"
                   "property float y\nproperty float z\nelement face 2\n"
                   "property list uchar int vertex_indices\nend_header\n0 0 0\n1 0 0\n0 1 0\n"
                   "1 nan 0\n3 0 1 2\n3 1 3 2\n")
        with pytest.raises(ValueError, match=r"vertex 3 .* not finite"):
            load_mesh(p)

    def test_crease_angle_only_for_files(self):
        with pytest.raises(ValueError, match="crease angle applies to mesh files"):
            get_mesh("sphere", 4, crease_angle=0.5)

    def test_render_cli_crease_angle(self, tmp_path):
        _write(tmp_path, "t.obj", TILTED_OBJ)
        base = ["render", "--mesh", "t.obj", "--size", "32", "32", "--json"]
        ok = [run_cli(*base, cwd=tmp_path), run_cli(*base, "--crease-angle", "45", cwd=tmp_path)]
        assert all(r.code == 0 for r in ok), [r.err for r in ok]
        for bad in ("-1", "180.5", "nan", "inf"):
            r = cli(*base, "--crease-angle", bad, cwd=tmp_path)
            assert r.code == 2 and "--crease-angle" in r.err and "[0, 180]" in r.err
        r = cli("render", "--mesh", "sphere", "--crease-angle", "30", cwd=tmp_path)
        assert r.code == 2 and "mesh files" in r.err
        _write(tmp_path, "n.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nv nan 1 0\nf 1 2 3\nf 2 4 3\n")
        r = cli("render", "--mesh", "n.obj", "--size", "32", "32", cwd=tmp_path)
        assert r.code == 2 and "vertex 4 (line 4) is not finite" in r.err
        assert r.err.count("\n") == 1


def test_render_bytes_identical_to_pillow_png(tmp_path):
    """write_image's PNG is exactly what Pillow writes for the array."""
    a = np.random.default_rng(0).integers(0, 256, (9, 7, 3), dtype=np.uint8)
    write_image(tmp_path / "a.png", a)
    buf = io.BytesIO()
    Image.fromarray(a).save(buf, format="PNG")
    assert (tmp_path / "a.png").read_bytes() == buf.getvalue()
