"""What the benchmarks ran on: one line naming the CPU, for results.json and the printouts.

Virtual machines often report only a family name ("AMD EPYC"); two such machines
here differed by 2x in speed, so the family and model numbers and the widest SIMD
level are added from /proc/cpuinfo where it exists.
"""

from __future__ import annotations

import platform
from pathlib import Path


def cpu_description(cpuinfo: str | None = None) -> str:
    """``"<model name> (family F, model M; AVX-512)"`` from ``/proc/cpuinfo`` (its text,
    or read from the file), else the platform's processor name.

    >>> cpu_description("model name : AMD EPYC\\ncpu family : 26\\nmodel : 2\\nflags : sse avx2 avx512f\\n")
    'AMD EPYC (family 26, model 2; AVX-512)'
    >>> cpu_description("model name : X\\nflags : sse2\\n")
    'X (SSE2)'
    """
    if cpuinfo is None:
        try:
            cpuinfo = Path("/proc/cpuinfo").read_text()
        except OSError:
            return platform.processor() or "unknown"
    fields = {}
    for line in cpuinfo.splitlines():
        key, _, value = line.partition(":")
        fields.setdefault(key.strip(), value.strip())      # the first CPU's
    name = fields.get("model name") or platform.processor() or "unknown"
    flags = set(fields.get("flags", "").split())
    simd = "AVX-512" if "avx512f" in flags else "AVX2" if "avx2" in flags else "SSE2"
    ids = [f"{k.split()[-1]} {fields[k]}" for k in ("cpu family", "model") if k in fields]
    return f"{name} ({', '.join(ids)}; {simd})" if ids else f"{name} ({simd})"
