"""The compiled engine's floor: the numba import guard, :func:`njit`, seven intrinsics
(``fma``, ``f2i``, ``i2f``, ``prefetch``: LLVM operations; ``unowned``: array views
that count no references; ``stream16`` and ``store_fence``: stores that bypass the
caches, and the fence that orders them; callable from compiled code only) and the one
thread pool of the process.

Every compiled function of :mod:`chebnorm.raster.engines.numba` is made by :func:`njit`:
cached, ``nogil``, no ``fastmath`` (every float operation is the numpy reference's, in
its order and dtype; LLVM does not contract a multiply-add into an FMA without
fast-math flags).  Without numba, or with its compiler turned off (``NUMBA_DISABLE_JIT=1``:
:data:`HAVE_NUMBA` False), :func:`njit` returns the Python function and the engine is not
offered (:func:`chebnorm.raster.engines.get_engine`).
"""

from __future__ import annotations

import os
import threading
import warnings
from concurrent.futures import ThreadPoolExecutor

from chebnorm.exceptions import NumbaCompileWarning

try:  # pragma: no cover - exercised by whichever environment runs the tests
    import numba
    from llvmlite import ir as _ir
    from numba.core import types as _types
    from numba.core.errors import NumbaWarning as _NumbaWarning
    from numba.core.extending import intrinsic as _intrinsic
    #: whether numba's compiler is off (``NUMBA_DISABLE_JIT=1``): its intrinsics cannot
    #: run as Python, so the engine is then not offered, as without numba
    JIT_DISABLED = bool(numba.config.DISABLE_JIT)
    #: whether numba is installed and compiles (else every function here runs as plain
    #: Python and ``render`` uses the numpy engine)
    HAVE_NUMBA = not JIT_DISABLED
    #: numba's ``objmode`` (a block of compiled code run by the interpreter, under the GIL)
    objmode = numba.objmode
except ImportError:  # pragma: no cover
    numba = None
    _NumbaWarning = None
    JIT_DISABLED = False
    HAVE_NUMBA = False
    objmode = None

# an implementation module of chebnorm.raster.engines.numba: the API is what chebnorm.raster.engines.numba exports
__all__: list[str] = []


#: seconds a warm-up (compile or cache load) may take before it is announced
ANNOUNCE_AFTER = 3.0
#: the announcement is made once per process
_ANNOUNCED = threading.Event()


def announce_slow(work, what: str = "the raster engine"):
    """Run ``work()``; if it takes longer than :data:`ANNOUNCE_AFTER` seconds,
    issue one :class:`NumbaCompileWarning` while it runs (once per process).

    numba's own warnings while it compiles (``NumbaWarning`` and its kinds: about
    chebnorm's kernels, nothing a caller can act on) are caught here.

    Parameters
    ----------
    work : callable
        The warm-up (compiles the kernels it calls).
    what : str
        What is being compiled, for the message.

    Returns
    -------
    object
        What ``work()`` returns.
    """
    done = threading.Event()

    def note():
        if not done.wait(ANNOUNCE_AFTER) and not _ANNOUNCED.is_set():
            _ANNOUNCED.set()
            warnings.warn_explicit(
                f"numba is compiling {what}: the first render of this kind on this machine "
                f"takes seconds (numba caches the code on disk for later processes); the "
                f"render's seconds do not count it", NumbaCompileWarning, "chebnorm", 0,
                module="chebnorm.raster")

    watcher = threading.Thread(target=note, name="chebnorm-compile-note", daemon=True)
    watcher.start()
    try:
        with warnings.catch_warnings():
            if _NumbaWarning is not None:
                warnings.simplefilter("ignore", _NumbaWarning)
            return work()
    finally:
        done.set()
        watcher.join()


def njit(fn=None, *, inline=False, nogil=True):
    """numba's ``njit`` (cached, ``nogil``, no fast-math, numpy's error model), usable
    as ``@njit`` or ``@njit(inline=True)``; ``inline``: inlined into its callers in
    numba's IR (per-pixel helpers: no call, no reference counting of the arrays passed
    in the inner loop).  Without numba, the function itself.

    Parameters
    ----------
    fn : callable, optional
        The function to compile (``@njit``); None for ``@njit(...)``.
    inline : bool
        Inline into callers (``inline="always"``) instead of calling.
    nogil : bool
        Release the GIL (False for a function with an ``objmode`` block, which takes it).

    Returns
    -------
    callable
        The compiled function (or, for ``@njit(...)``, the decorator).
    """
    def deco(f):
        if not HAVE_NUMBA:
            return f
        return numba.njit(cache=True, nogil=nogil, fastmath=False, error_model="numpy",
                          inline="always" if inline else "never")(f)
    return deco(fn) if fn is not None else deco


if HAVE_NUMBA:
    @_intrinsic
    def fma(typingctx, a, b, c):
        """``a * b + c`` rounded once (LLVM's ``fma``)."""
        sig = _types.float64(_types.float64, _types.float64, _types.float64)

        def codegen(context, builder, signature, args):
            d = _ir.DoubleType()
            fn = builder.module.declare_intrinsic("llvm.fma", [d], _ir.FunctionType(d, [d, d, d]))
            return builder.call(fn, args)
        return sig, codegen
else:  # pragma: no cover
    def fma(a, b, c):
        raise RuntimeError("numba is not installed")


if HAVE_NUMBA:
    @_intrinsic
    def f2i(typingctx, x):
        """The bits of a float64 as an int64."""
        sig = _types.int64(_types.float64)

        def codegen(context, builder, signature, args):
            return builder.bitcast(args[0], _ir.IntType(64))
        return sig, codegen

    @_intrinsic
    def i2f(typingctx, i):
        """The float64 whose bits are the int64 ``i``."""
        sig = _types.float64(_types.int64)

        def codegen(context, builder, signature, args):
            return builder.bitcast(args[0], _ir.DoubleType())
        return sig, codegen

    @_intrinsic
    def unowned(typingctx, arr):
        """Views of ``arr`` (an array, or a tuple of arrays and other values: each array
        viewed, the rest passed through) that own no reference: the same data, shape and
        strides with a null meminfo, so passing them to a compiled function that is not
        inlined costs no atomic reference count (two threads counting the references of
        the same array bounce its cache line between their cores).  A view must not
        outlive the arrays' owner: a kernel's own arguments, or arrays the kernel keeps
        referenced until its views are no longer used."""
        if isinstance(arr, _types.Array):
            arrays = None
        elif isinstance(arr, _types.BaseTuple):
            arrays = [isinstance(t, _types.Array) for t in arr.types]
        else:
            return None
        sig = arr(arr)

        def view(context, builder, typ, value):
            from numba.core import cgutils
            src = context.make_array(typ)(context, builder, value=value)
            out = context.make_array(typ)(context, builder)
            for name in ("data", "shape", "strides", "itemsize", "nitems"):
                setattr(out, name, getattr(src, name))
            out.meminfo = cgutils.get_null_value(out.meminfo.type)
            out.parent = cgutils.get_null_value(out.parent.type)
            return out._getvalue()

        def codegen(context, builder, signature, args):
            if arrays is None:
                return view(context, builder, arr, args[0])
            items = []
            for k, (typ, is_array) in enumerate(zip(arr.types, arrays)):
                item = builder.extract_value(args[0], k)
                if is_array:
                    item = view(context, builder, typ, item)
                else:
                    context.nrt.incref(builder, typ, item)
                items.append(item)
            return context.make_tuple(builder, arr, items)
        return sig, codegen

    @_intrinsic
    def prefetch(typingctx, arr, i):
        """A hint to bring the cache line of element ``i`` of the C-contiguous array
        ``arr`` (``i`` counted in its flat order; ``0 <= i < arr.size``) into the cache
        (LLVM's ``prefetch``: no value, no fault, no effect on the results)."""
        if not (isinstance(arr, _types.Array) and arr.layout == "C"):
            return None
        sig = _types.void(arr, _types.int64)

        def codegen(context, builder, signature, args):
            ary = context.make_array(signature.args[0])(context, builder, value=args[0])
            i8p = _ir.IntType(8).as_pointer()
            i32 = _ir.IntType(32)
            size = context.get_abi_sizeof(context.get_data_type(signature.args[0].dtype))
            off = builder.mul(args[1], _ir.Constant(_ir.IntType(64), size))
            ptr = builder.gep(builder.bitcast(ary.data, i8p), [off])
            fn = builder.module.declare_intrinsic("llvm.prefetch", [i8p],
                                                  _ir.FunctionType(_ir.VoidType(),
                                                                   [i8p, i32, i32, i32]))
            # a read (0), kept in every cache level (3), of data (1)
            builder.call(fn, [ptr, _ir.Constant(i32, 0), _ir.Constant(i32, 3),
                              _ir.Constant(i32, 1)])
            return context.get_dummy_value()
        return sig, codegen

    @_intrinsic
    def stream16(typingctx, dst, d, src, s):
        """Copy the 16 bytes at byte offset ``s`` of array ``src`` to byte offset ``d``
        of array ``dst`` with a non-temporal store (LLVM ``!nontemporal``: the line is
        written to memory without being read into the cache first).  The destination
        address must be a multiple of 16 and both ranges inside their (C-contiguous)
        arrays; the stores are weakly ordered: :func:`store_fence` before another
        thread reads them."""
        if not all(isinstance(a, _types.Array) and a.layout == "C" for a in (dst, src)):
            return None
        sig = _types.void(dst, _types.int64, src, _types.int64)

        def codegen(context, builder, signature, args):
            i8p = _ir.IntType(8).as_pointer()
            vt = _ir.VectorType(_ir.IntType(64), 2)
            a = context.make_array(signature.args[0])(context, builder, value=args[0])
            b = context.make_array(signature.args[2])(context, builder, value=args[2])
            dp = builder.bitcast(builder.gep(builder.bitcast(a.data, i8p), [args[1]]),
                                 vt.as_pointer())
            sp = builder.bitcast(builder.gep(builder.bitcast(b.data, i8p), [args[3]]),
                                 vt.as_pointer())
            v = builder.load(sp, align=1)
            st = builder.store(v, dp, align=16)
            st.set_metadata("nontemporal",
                            builder.module.add_metadata([_ir.Constant(_ir.IntType(32), 1)]))
            return context.get_dummy_value()
        return sig, codegen

    @_intrinsic
    def store_fence(typingctx):
        """A store fence (``sfence`` on x86, LLVM's ``fence release`` elsewhere): the
        stores of :func:`stream16` before it are visible to other threads after it."""
        sig = _types.void()

        def codegen(context, builder, signature, args):
            if "x86" in builder.module.triple or "i386" in builder.module.triple:
                fn = builder.module.declare_intrinsic("llvm.x86.sse.sfence", [],
                                                      _ir.FunctionType(_ir.VoidType(), []))
                builder.call(fn, [])
            else:  # pragma: no cover - not x86
                builder.fence("release")
            return context.get_dummy_value()
        return sig, codegen
else:  # pragma: no cover
    def unowned(arr):
        raise RuntimeError("numba is not installed")

    def prefetch(arr, i):
        raise RuntimeError("numba is not installed")

    def stream16(dst, d, src, s):
        raise RuntimeError("numba is not installed")

    def store_fence():
        raise RuntimeError("numba is not installed")

    def f2i(x):
        raise RuntimeError("numba is not installed")

    def i2f(i):
        raise RuntimeError("numba is not installed")


def threads() -> int:
    """Threads to split a frame over: the CPUs this process may run on (at most 8).

    Returns
    -------
    int
        Between 1 and 8.
    """
    try:
        n = len(os.sched_getaffinity(0))
    except AttributeError:  # pragma: no cover - not Linux
        n = os.cpu_count() or 1
    return max(1, min(8, n))


#: the thread pool of this process: {pid: executor} (a forked child makes its own)
_POOL: dict = {}


def pool():
    """This process's thread pool (a forked child makes its own).

    Returns
    -------
    concurrent.futures.ThreadPoolExecutor
        The pool, :func:`threads` workers.
    """
    ex = _POOL.get(os.getpid())
    if ex is None:
        _POOL.clear()
        ex = _POOL[os.getpid()] = ThreadPoolExecutor(max_workers=threads(),
                                                      thread_name_prefix="chebnorm-raster")
    return ex


def run(jobs):
    """Run ``[(kernel, args), ...]`` (compiled with ``nogil``) at once on :func:`pool`;
    their results in order.

    Parameters
    ----------
    jobs : sequence of (callable, tuple)
        Compiled ``nogil`` kernels and their arguments.

    Returns
    -------
    list
        Each kernel's result, in the order of ``jobs``.
    """
    if len(jobs) == 1:
        return [jobs[0][0](*jobs[0][1])]
    futures = [pool().submit(fn, *args) for fn, args in jobs]
    return [f.result() for f in futures]


def run_with_caller(jobs):
    """Run ``[(kernel, args), ...]`` (compiled with ``nogil``): the first on this thread,
    the others on :func:`pool` (whose threads may be busy with the frame's
    background); their results in order.

    Parameters
    ----------
    jobs : sequence of (callable, tuple)
        Compiled ``nogil`` kernels and their arguments.

    Returns
    -------
    list
        Each kernel's result, in the order of ``jobs``.
    """
    if len(jobs) == 1:
        return [jobs[0][0](*jobs[0][1])]
    futures = [pool().submit(fn, *args) for fn, args in jobs[1:]]
    first = jobs[0][0](*jobs[0][1])
    return [first] + [f.result() for f in futures]
