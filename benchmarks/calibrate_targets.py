"""Calibrate the per-target cost model (chebnorm.hw.target_model) against yosys.

Synthesizes a fixed set of designs on every target, fits the model's constants
by non-negative least squares on the relative error, and prints the constants
and the spread (largest max(model/yosys, yosys/model) per target) as JSON; with
``--write FILE`` also writes them (benchmarks/target_calibration.json).

    python benchmarks/calibrate_targets.py --write benchmarks/target_calibration.json
"""

from __future__ import annotations

import argparse
import json
import sys
import time

import numpy as np
from scipy.optimize import nnls

from chebnorm.approx import fit_target
from chebnorm.approx.piecewise_fit import piecewise_fit
from chebnorm.hw.hdl import module_text
from chebnorm.hw.horner import design_horner
from chebnorm.hw.piecewise import design_piecewise
from chebnorm.hw.target_model import model_terms, piecewise_features, horner_features
from chebnorm.hw.targets import synthesize_target, target_names

#: (expression, interval, in/out bits, degree, index bits k, coefficient fractional bits)
PIECEWISE = [
    ("1/sqrt(1+3*x)", ("0", "1"), 16, 2, 5, 17),
    ("1/sqrt(1+3*x)", ("0", "1"), 16, 1, 7, 19),
    ("1/sqrt(1+3*x)", ("0", "1"), 16, 3, 3, 18),
    ("1/sqrt(1+3*x)", ("0", "1"), 16, 2, 6, 18),
    ("1/sqrt(x)", ("1", "4"), 12, 1, 4, 14),
    ("1/sqrt(x)", ("1", "4"), 12, 2, 2, 14),
    ("1/sqrt(x)", ("1", "4"), 12, 1, 6, 14),
    ("log(1+x)", ("0", "1"), 16, 2, 4, 18),
    ("log(1+x)", ("0", "1"), 12, 3, 2, 14),
    ("log(1+x)", ("0", "1"), 16, 1, 5, 18),
]
#: (target, degree, in/out bits, coefficient bits) of single Horner designs
HORNER = [("dichotomy", 1, 12, 14), ("dichotomy", 2, 12, 16), ("dichotomy", 3, 16, 20)]
#: held out of the fit: the model's ratio to yosys on designs it never saw
HOLDOUT = [
    ("exp(x)", ("0", "1"), 14, 2, 4, 16),
    ("sin(x)", ("0", "1"), 16, 1, 6, 18),
    ("1/sqrt(1+3*x)", ("0", "1"), 20, 2, 7, 21),
    ("1/(1+x)", ("0", "1"), 12, 3, 1, 14),
]


def designs(piecewise=PIECEWISE, horner=HORNER):
    for expr, iv, bits, deg, k, f in piecewise:
        t = piecewise_fit(expr, iv, deg, segments=2 ** k, coef_frac_bits=f, name="cal")
        d = design_piecewise(t, bits, bits)
        yield f"pw {expr} d{deg} 2^{k} {bits}b", module_text(d, "verilog"), d.module_name, \
            piecewise_features(d)
    for tgt, deg, bits, cb in horner:
        d = design_horner(fit_target(tgt, deg), bits, bits, coef_bits=cb)
        yield f"horner {tgt} d{deg} {bits}b", module_text(d, "verilog"), d.module_name, \
            horner_features(d)


def main(argv=None) -> int:
    ap = argparse.ArgumentParser()
    ap.add_argument("--write", default=None)
    ap.add_argument("--reuse", default=None,
                    help="refit on the yosys scores recorded in this JSON (no synthesis)")
    args = ap.parse_args(argv)
    rows = []
    t0 = time.time()
    known = {}
    if args.reuse:
        with open(args.reuse, encoding="utf-8") as fh:
            known = {(r["design"], r["target"]): r["yosys"] for r in json.load(fh)["rows"]}
    for label, text, top, feat in designs():
        for target in target_names():
            score = known.get((label, target))
            if score is None:
                score = synthesize_target(text, top, target).score
            rows.append((label, target, model_terms(feat, target), score))
            print(f"{label:40s} {target:10s} {score:9.1f}", file=sys.stderr)
    out = {"constants": {}, "spread": {}, "rows": []}
    for target in target_names():
        rs = [r for r in rows if r[1] == target]
        keys = ["rom", "mul", "add"]
        y = np.array([r[3] for r in rs])
        fixed = np.array([r[2]["fixed"] for r in rs])
        a = np.array([[r[2][k] for k in keys] for r in rs])
        # relative error: divide each row by its yosys score
        c, _ = nnls(a / y[:, None], (y - fixed) / y)
        c = [round(float(v), 4) for v in c]
        pred = a @ np.array(c) + fixed
        ratio = np.maximum(pred / y, y / pred)
        out["constants"][target] = dict(zip(keys, c))
        out["spread"][target] = round(float(ratio.max()), 3)
        for r, p in zip(rs, pred):
            out["rows"].append({"design": r[0], "target": target, "yosys": r[3],
                                "model": round(float(p), 1)})
    out["holdout"] = []
    for label, text, top, feat in designs(HOLDOUT, ()):
        for target in target_names():
            real = synthesize_target(text, top, target).score
            c = out["constants"][target]
            t = model_terms(feat, target)
            pred = c["rom"] * t["rom"] + c["mul"] * t["mul"] + c["add"] * t["add"] + t["fixed"]
            out["holdout"].append({"design": label, "target": target, "yosys": real,
                                   "model": round(pred, 1),
                                   "ratio": round(max(pred / real, real / pred), 3)})
            print(f"holdout {label:32s} {target:10s} {real:9.1f}", file=sys.stderr)
    out["seconds"] = round(time.time() - t0, 1)
    text = json.dumps(out, indent=2, sort_keys=True) + "\n"
    print(text)
    if args.write:
        with open(args.write, "w", encoding="utf-8") as fh:
            fh.write(text)
    return 0


if __name__ == "__main__":
    sys.exit(main())
