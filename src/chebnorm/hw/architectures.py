"""The architectures ``chebnorm design`` chooses among, priced on one target.

Besides the one-width piecewise evaluator of :mod:`chebnorm.hw.piecewise_search`
(the Pareto search), three architectures compete for the same accuracy:

* ``piecewise-sized`` -- the piecewise ROM + Horner evaluator with a width per
  coefficient, ``t`` truncated per step and truncated products
  (:func:`chebnorm.hw.piecewise.design_piecewise` with ``widths="auto"``),
  certified per segment in exact interval arithmetic; multipliers
  ``truncated`` on LUT targets, ``full`` where a DSP takes them (xc7);
* ``multipartite`` -- a table-and-add evaluator with no multiplier
  (:func:`chebnorm.hw.multipartite.design_multipartite`), certified over every
  input code;
* ``table`` -- one ROM entry per input code, correctly rounded where proved
  (:func:`chebnorm.hw.plain_table.design_plain_table`); built only when its
  ROM is at most :data:`MAX_TABLE_ROM_BITS` bits (else it cannot win: it is
  reported with its ROM size).

Every candidate is synthesized on the target
(:func:`chebnorm.hw.targets.synthesize_target`) and the lowest score wins.
Accuracy is one of: ``max_error`` (certified ``<= E``), faithful (certified
``< 1`` unit of the output's last place) or correctly rounded (every code
equal to the proved rounding of ``f``: only a plain table is built for it,
the other architectures err by up to one unit and are reported as such).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

from chebnorm.approx.piecewise_fit import piecewise_fit
from chebnorm.approx.piecewise_table import MAX_COEF_FRAC_BITS

from .hdl import module_text
from .multipartite import design_multipartite
from .piecewise import design_piecewise
from .plain_table import design_plain_table
from .targets import get_target, synthesize_target

__all__ = ["Candidate", "ACCURACIES", "MAX_TABLE_ROM_BITS", "architecture_candidates"]

#: the accuracy specs ``design`` takes
ACCURACIES = ("max-error", "faithful", "correctly-rounded")
#: a plain table larger than this many ROM bits is not built (2^16 codes x 18 bits is
#: 1.2 Mbit: 16k yosys cells, 7k LUT on xc7 -- it cannot win against a multipartite)
MAX_TABLE_ROM_BITS = 1 << 18


@dataclass(frozen=True)
class Candidate:
    """One architecture's best design for the spec, with its target figures.

    Attributes
    ----------
    architecture : str
        ``piecewise-sized``, ``multipartite`` or ``table``.
    description : str
        Its parameters in one line.
    design : object or None
        The design (None when it was not built: see ``note``).
    error : float or None
        Its certified maximum error ``|y - f(x)|``.
    ulp : float or None
        One unit of its output's last place.
    cost : TargetCost or None
        Its synthesis on the target.
    note : str
        Why it was not built or cannot meet the spec (empty otherwise).

    Examples
    --------
    >>> Candidate("table", "2^24 entries", note="not built").line()
    'table: 2^24 entries -- not built'
    """

    architecture: str
    description: str
    design: object = None
    error: float | None = None
    ulp: float | None = None
    cost: object = None
    note: str = ""

    @property
    def verilog(self) -> str:
        """The candidate's Verilog module (its top is ``design.module_name``)."""
        d = self.design
        return d.verilog() if hasattr(d, "verilog") else module_text(d, "verilog")

    def line(self) -> str:
        """One line: the architecture, its parameters, cost and error."""
        if self.design is None:
            return f"{self.architecture}: {self.description} -- {self.note}"
        cost = "not synthesized" if self.cost is None else self.cost.line()
        return (f"{self.architecture}: {self.description}: {cost}; certified error "
                f"{self.error:.4e} ({self.error / self.ulp:.3f} ulp)")


def _sized(expr, interval, in_bits, out_bits, degrees, k_start, max_error, var, name, target):
    """Every sized piecewise design that meets the error at the first segment
    counts from ``k_start`` on: ``[(degree, design, description)]``."""
    mult = "full" if get_target(target).name == "xc7" else "truncated"
    found = []
    for degree in degrees:
        k0 = k_start.get(degree)
        for k in range(k0, min(k0 + 3, in_bits - 2) + 1) if k0 is not None else ():
            f_hi = out_bits + 10 if max_error is None else math.ceil(-math.log2(max_error)) + 10
            t = piecewise_fit(expr, interval, degree, segments=2 ** k,
                              coef_frac_bits=min(f_hi, MAX_COEF_FRAC_BITS), centered=degree > 0,
                              var=var, name=f"{name}_d{degree}")
            try:
                d = design_piecewise(t, in_bits, out_bits, widths="auto", max_error=max_error,
                                     multipliers=mult)
            except ValueError:  # not reachable at this segment count
                continue
            found.append((degree, d, f"degree {degree}, {2 ** k} centred segments, ROM "
                          f"{sum(d.rom_bits) << k} bits, {mult} multipliers"))
    return found


def _cheapest_per_degree(cands: list[Candidate]) -> list[Candidate]:
    """Per degree, the sized candidate of the lowest synthesized score (or, not
    synthesized, of the fewest ROM bits)."""
    best: dict[int, Candidate] = {}
    for c in cands:
        d = c.design
        key = (c.cost.score if c.cost is not None else sum(d.rom_bits) << d.index_bits,
               d.index_bits)
        old = best.get(d.degree)
        if old is None or key < old[0]:
            best[d.degree] = (key, c)
    return [best[k][1] for k in sorted(best)]


def architecture_candidates(expr, interval, in_bits: int, out_bits: int, *, accuracy: str,
                            max_error=None, degrees=(1, 2, 3), k_start=None, var: str = "x",
                            name: str = "design", target: str = "generic",
                            synth: bool = True) -> list[Candidate]:
    """The other architectures' best designs for the spec (module docstring).

    ``k_start`` maps a degree to the index bits at which the one-width search
    first met the error (the sized search starts there). ``accuracy``: one of
    :data:`ACCURACIES`; ``max_error`` its bound for ``"max-error"``.

    Examples
    --------
    >>> cs = architecture_candidates("1/sqrt(1+3*x)", ("0", "1"), 6, 6,
    ...                              accuracy="correctly-rounded", synth=False)
    >>> [(c.architecture, c.design is not None) for c in cs]
    [('piecewise-sized', False), ('multipartite', False), ('table', True)]
    >>> cs[-1].error <= cs[-1].ulp / 2
    True
    """
    if accuracy not in ACCURACIES:
        raise ValueError(f"accuracy {accuracy!r}; accepted: {', '.join(ACCURACIES)}")
    e = max_error if accuracy == "max-error" else None
    out: list[Candidate] = []
    rom = (2 ** in_bits) * out_bits
    if accuracy == "correctly-rounded":
        for arch in ("piecewise-sized", "multipartite"):
            out.append(Candidate(arch, "faithful at best", note="errs by up to one unit of the "
                                 "output's last place; a correctly rounded output needs the "
                                 "proved rounding of every code (a plain table)"))
    else:
        sized = _sized(expr, interval, in_bits, out_bits, degrees, k_start or {}, e, var,
                       f"{name}_sized", target)
        if not sized:
            out.append(Candidate("piecewise-sized", "no design", note="the sized search met "
                                 "the error at no degree and segment count tried"))
        for _degree, d, text in sized:
            b = d.budget()
            out.append(Candidate("piecewise-sized", text, d, float(b["total"]),
                                 float(b["y_lsb"])))
        if in_bits <= 20:
            m = design_multipartite(expr, interval, in_bits, out_bits, max_error=e,
                                    faithful=e is None, var=var, name=f"{name}_mp")
            out.append(Candidate("multipartite", f"{len(m.offsets)} offset tables, ROM "
                                 f"{m.rom_bits} bits", m, float(m.certificate.upper),
                                 2.0 ** -m.y_format.frac_bits))
    if rom <= MAX_TABLE_ROM_BITS:
        p = design_plain_table(expr, interval, in_bits, out_bits, var=var, name=f"{name}_table")
        ok = accuracy != "correctly-rounded" or p.correctly_rounded
        out.append(Candidate("table", f"{2 ** in_bits} entries, ROM {p.rom_bits} bits"
                             + (", correctly rounded (proved)" if p.correctly_rounded else ""),
                             p if ok else None, float(p.certificate.upper),
                             2.0 ** -p.y_format.frac_bits,
                             note="" if ok else f"{p.unproved} codes' rounding not proved"))
    else:
        out.append(Candidate("table", f"{2 ** in_bits} entries", note=f"ROM of {rom} bits, over "
                             f"{MAX_TABLE_ROM_BITS}: not built (it cannot win)"))
    if synth:
        out = [c if c.design is None else
               Candidate(c.architecture, c.description, c.design, c.error, c.ulp,
                         synthesize_target(c.verilog, c.design.module_name, target))
               for c in out]
    sized = [c for c in out if c.architecture == "piecewise-sized" and c.design is not None]
    keep = set(map(id, _cheapest_per_degree(sized)))
    return [c for c in out if c.architecture != "piecewise-sized" or c.design is None
            or id(c) in keep]
