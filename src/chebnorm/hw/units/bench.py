"""Test vectors, vector files and self-checking test benches of every unit."""

from __future__ import annotations

import numpy as np

from ..fixed import check_width
from ..hdl.unit_bench import row_layout
from ..hdl.unit_bench import unit_testbench as _bench
from .base import EXHAUSTIVE_BITS, Port, UnitDesign

# an implementation module of chebnorm.hw.units: the API is what chebnorm.hw.units exports
__all__: list[str] = []


def unit_normals(rng, n: int) -> np.ndarray:
    """``n`` random unit vectors ``(n, 3)``.

    Parameters
    ----------
    rng : numpy.random.Generator
        The random source.
    n : int
        How many, ``>= 0``.

    Returns
    -------
    numpy.ndarray
        Shape ``(n, 3)``, each row of norm 1.

    Examples
    --------
    >>> v = unit_normals(np.random.default_rng(0), 4)
    >>> v.shape, bool(np.allclose(np.linalg.norm(v, axis=1), 1))
    ((4, 3), True)
    """
    v = rng.normal(size=(n, 3))
    return v / np.linalg.norm(v, axis=1, keepdims=True)


def near(rng, a: np.ndarray, psi: float) -> np.ndarray:
    """Unit vectors at angles in [0, psi] from the rows of ``a``.

    Parameters
    ----------
    rng : numpy.random.Generator
        The random source.
    a : numpy.ndarray
        Unit vectors, shape ``(n, 3)``.
    psi : float
        The largest angle, radians; the first four rows take 0, ``psi``, ``psi/2``, 1e-3.

    Returns
    -------
    numpy.ndarray
        Shape ``(n, 3)``: unit vectors at uniform random angles in ``[0, psi]``.

    Examples
    --------
    >>> rng = np.random.default_rng(0)
    >>> a = unit_normals(rng, 100)
    >>> b = near(rng, a, 0.5)
    >>> bool(np.all(np.arccos(np.clip(np.sum(a * b, axis=1), -1, 1)) <= 0.5 + 1e-12))
    True
    """
    t = rng.normal(size=a.shape)
    t -= np.sum(t * a, axis=1, keepdims=True) * a
    t /= np.maximum(np.linalg.norm(t, axis=1, keepdims=True), 1e-300)
    th = rng.uniform(0, psi, (len(a), 1))
    th[:4, 0] = [0.0, psi, psi / 2, 1e-3][:len(a)]
    return a * np.cos(th) + t * np.sin(th)


def codes(v: np.ndarray, f: int, w: int) -> np.ndarray:
    """``w``-bit codes with ``f`` fractional bits of the values ``v`` (nearest, saturated).

    Parameters
    ----------
    v : numpy.ndarray
        The values.
    f : int
        Fractional bits.
    w : int
        Signed code width, ``>= 1``.

    Returns
    -------
    numpy.ndarray of int64
        ``v * 2**f`` rounded to nearest (ties to even), clamped to
        ``[-2**(w-1), 2**(w-1) - 1]``.

    Examples
    --------
    >>> codes(np.array([0.5, -1.0, 3.0]), 4, 6).tolist()   # 3.0 saturates to 31/16
    [8, -16, 31]
    """
    return np.clip(np.rint(v * 2.0 ** f), -(1 << (w - 1)), (1 << (w - 1)) - 1).astype(np.int64)


def _rand(rng, n: int, port: Port) -> np.ndarray:
    lo = -(1 << (port.bits - 1)) if port.signed else 0
    hi = (1 << (port.bits - 1)) if port.signed else (1 << port.bits)
    return rng.integers(lo, hi, n, dtype=np.int64)


def edges(port: Port) -> list[int]:
    """The extreme codes of ``port``: min, -1, 0, 1, max (those it has).

    Parameters
    ----------
    port : Port
        The port.

    Returns
    -------
    list of int
        The codes among min, -1, 0, 1, max that the port holds, ascending.

    Examples
    --------
    >>> edges(Port("n_x", 5)), edges(Port("thr", 4, signed=False))
    ([-16, -1, 0, 1, 15], [0, 1, 15])
    """
    if port.signed:
        b = port.bits
        return sorted({-(1 << (b - 1)), -1, 0, 1, (1 << (b - 1)) - 1})
    return sorted({0, 1, (1 << port.bits) - 1})


def unit_vectors(unit: UnitDesign, count: int = 2000, seed: int = 0) -> dict:
    """Input rows (name -> int64 array) for the test bench of ``unit``: every
    input code when the inputs have at most 16 bits; else edge cases (each
    input takes each of its extreme codes -- min, -1, 0, 1, max -- while the
    others cycle through theirs), ``count`` realistic rows
    (quantized unit normals at angles inside the table's interval, and
    their ``z``/threshold) and ``count`` rows of uniformly random codes.

    Parameters
    ----------
    unit : UnitDesign
        The sized unit (:func:`~chebnorm.hw.units.design_unit`).
    count : int, default 2000
        Realistic and random rows each, 1 to 10**6.
    seed : int, default 0
        The seed of ``numpy.random.default_rng``.

    Returns
    -------
    dict of str to numpy.ndarray
        Input port name -> codes, one per row.

    Raises
    ------
    ValueError
        If ``count`` is out of range.

    Examples
    --------
    >>> from chebnorm.hw.units import design_unit
    >>> rows = unit_vectors(design_unit("classic", frac_bits=3, comp_bits=5))
    >>> sorted(rows), len(rows["n_x"]) == 2 ** 15   # 15 input bits: every code
    (['n_x', 'n_y', 'n_z'], True)
    """
    count = check_width(count, "vectors", 1, 10 ** 6)
    return unit.spec.vector_rows(unit, np.random.default_rng(seed), count)


def combinational_rows(unit: UnitDesign, rng, count: int, realistic) -> dict:
    """The rows of :func:`unit_vectors` of a combinational unit;
    ``realistic(rng, a)`` makes its realistic rows from the unit normals ``a``.

    Parameters
    ----------
    unit : UnitDesign
        The sized unit (:func:`~chebnorm.hw.units.design_unit`).
    rng : numpy.random.Generator
        The random source.
    count : int
        Realistic and random rows each.
    realistic : callable
        ``realistic(rng, a) -> dict`` of input port -> codes, from unit normals ``a``
        of shape ``(count, 3)``.

    Returns
    -------
    dict of str to numpy.ndarray
        Input port name -> codes: every code, or edges, realistic and random rows.

    Examples
    --------
    >>> from chebnorm.hw.units import design_unit
    >>> u = design_unit("classic", frac_bits=6)
    >>> rows = combinational_rows(u, np.random.default_rng(0), 10, lambda rng, a: {
    ...     f"n_{c}": codes(a[:, i], 6, 8) for i, c in enumerate("xyz")})
    >>> len(rows["n_x"])   # 40 edge rows, 10 realistic, 10 random
    60
    """
    ins = unit.inputs
    if sum(p.bits for p in ins) <= EXHAUSTIVE_BITS:
        grids = np.meshgrid(*[np.arange(edges(p)[0], edges(p)[-1] + 1) for p in ins],
                            indexing="ij")
        return {p.name: g.ravel().astype(np.int64) for p, g in zip(ins, grids)}
    rows = {p.name: [] for p in ins}

    def add(d):
        for k in rows:
            rows[k].append(np.asarray(d[k], dtype=np.int64))
    # edge cases: each input takes each of its extreme codes, the others cycle through theirs
    ends = [edges(p) for p in ins]
    n_edge = max(len(e) for e in ends) * 8
    for j in range(n_edge):
        add({p.name: [e[(j + i * (j // len(e) + 1)) % len(e)]] for i, (p, e) in
             enumerate(zip(ins, ends))})
    add(realistic(rng, unit_normals(rng, count)))
    add({p.name: _rand(rng, count, p) for p in ins})
    return {k: np.concatenate(v) for k, v in rows.items()}


def unit_vector_file(unit: UnitDesign, inputs: dict) -> str:
    """Rows ``{inputs, expected outputs}`` in hex (``$readmemh``).

    Parameters
    ----------
    unit : UnitDesign
        The sized unit (:func:`~chebnorm.hw.units.design_unit`).
    inputs : dict of str to numpy.ndarray
        Input port name -> codes (:func:`unit_vectors`).

    Returns
    -------
    str
        One hex word per row: the inputs, then the model's outputs.

    Raises
    ------
    ValueError
        If an input or output code does not fit its port (an internal sizing error).

    Examples
    --------
    >>> from chebnorm.hw.units import design_unit
    >>> u = design_unit("classic", frac_bits=3, comp_bits=5)
    >>> unit_vector_file(u, {"n_x": [6], "n_y": [8], "n_z": [0]})   # n = (6, 8, 0) -> u = (4, 6, 0)
    '0c8010c0\\n'
    """
    outs = unit.evaluate(inputs)
    layout, total = row_layout(unit.ports)
    vals = {**inputs, **outs}
    n = len(next(iter(inputs.values())))
    row = [0] * n
    for p, _, lo in layout:
        v = np.asarray(vals[p.name], dtype=np.int64)
        vmin = -(1 << (p.bits - 1)) if p.signed else 0
        vmax = (1 << (p.bits - 1)) - 1 if p.signed else (1 << p.bits) - 1
        if v.min() < vmin or v.max() > vmax:
            raise ValueError(f"{unit.module_name}: {p.name} takes {int(v.min())}..{int(v.max())}, "
                             f"outside its {p.bits}-bit port (internal sizing error)")
        mask = (1 << p.bits) - 1
        for i, x in enumerate(v.tolist()):
            row[i] |= (x & mask) << lo
    digits = (total + 3) // 4
    return "".join(f"{r:0{digits}x}\n" for r in row)


def unit_testbench(unit: UnitDesign, count: int, vectors: str | None = None,
                   language: str = "verilog") -> str:
    """A self-checking test bench of ``count`` rows read from ``vectors``
    (printed by :func:`chebnorm.hw.hdl.unit_bench.unit_testbench`).

    Parameters
    ----------
    unit : UnitDesign
        The sized unit (:func:`~chebnorm.hw.units.design_unit`).
    count : int
        How many rows the vector file holds.
    vectors : str or None, default None
        The vector file name; None: ``NAME.hex``.
    language : {"verilog", "vhdl"}, default "verilog"
        The bench's language.

    Returns
    -------
    str
        The bench text.

    Raises
    ------
    ValueError
        If ``language`` is unknown.

    Examples
    --------
    >>> from chebnorm.hw.units import design_unit
    >>> tb = unit_testbench(design_unit("classic", frac_bits=6), 100)
    >>> tb.splitlines()[0][:40], "localparam COUNT = 100;" in tb
    ('// tb_chebnorm_classic_unit: self-checki', True)
    >>> "constant COUNT : natural := 100;" in unit_testbench(design_unit("classic"), 100,
    ...                                                    language="vhdl")
    True
    """
    return _bench(unit.module_name, unit.ports, count, language, clocked=unit.clocked,
                  vectors=vectors)
