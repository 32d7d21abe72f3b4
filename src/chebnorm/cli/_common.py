"""Helpers shared by the subcommands."""

from __future__ import annotations

import json
import shlex


def command_line(args) -> str:
    """The command that made an output, for provenance banners."""
    return " ".join(shlex.quote(a) for a in getattr(args, "argv", ["chebnorm"]))


def print_json(obj) -> None:
    """Deterministic JSON on stdout: sorted keys, shortest float repr."""
    print(json.dumps(obj, sort_keys=True, indent=2, allow_nan=False))
