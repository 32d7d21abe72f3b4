"""``chebnorm targets``: the registry of named approximation targets."""

from __future__ import annotations

from chebnorm.approx import TARGETS, target_names

from .common import print_json


def register(sub) -> None:
    p = sub.add_parser("targets", help="list the registered approximation targets")
    p.add_argument("--psi-max", default="pi/4", help="largest span angle in radians (default pi/4)")
    p.add_argument("--json", action="store_true")
    p.set_defaults(func=run)


def run(args) -> int:
    rows = []
    for name in target_names():
        t = TARGETS[name]
        lo, hi = t.interval(args.psi_max)
        rows.append({"name": name, "expression": t.expression, "variable": t.variable,
                     "interval": [lo, hi], "degrees": list(t.degrees), "kind": t.kind,
                     "meaning": t.meaning})
    if args.json:
        print_json(rows)
    else:
        for r in rows:
            print(f"{r['name']:10s} {r['expression']:18s} {r['variable']} in [{r['interval'][0]}, "
                  f"{r['interval'][1]}]  degrees {r['degrees']} ({r['kind']}): {r['meaning']}")
    return 0
