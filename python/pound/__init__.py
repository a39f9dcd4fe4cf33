"""pound — nonsmooth dynamics of pounding structures, from Python.

A ctypes binding of libpound.so: the same library calls as the `pound`
command line, so the numbers are the CLI's to the last bit.

    import pound
    r = pound.simulate(pulse="sine", Tp=0.3, T0=3, ap=4, gap=0.004, eps=0.6)
    r.umax, r.Pi1, r.gamma, r.impacts     # as `pound simulate --json`
    r.t, r.u                              # the history (NumPy arrays)

The library: $POUND_LIBRARY (a path), else the installed libpound.so.0,
else the build tree (../build/libpound.so next to this package's source).
Errors raise pound.PoundError (InputError for PD_EINVAL, ParseError,
FileError, NumericalError, SolverError, BudgetError) with the library's
message and status.  pound.plot draws results with Matplotlib (imported
when a figure is asked for).  Every public function is annotated (PEP 484;
the package ships py.typed); values are in SI units, stated in each
docstring.
"""
from ._lib import (BudgetError, FileError, InputError, LayoutError, NumericalError, ParseError,
                   PoundError, PoundMemoryError, SolverError, library_path, version)
from ._case import Record
from ._osc import Result, compare, converge, dt_range, simulate, stats_of
from ._scene import Scene, scene, simulate_scene
from ._spectrum import spectrum
from ._lcp import lcp, read_lcp, record
from . import plot

__version__ = "0.13.0"

__all__ = ["simulate", "stats_of", "compare", "converge", "dt_range", "spectrum", "lcp", "read_lcp",
           "scene", "simulate_scene", "Scene", "record", "Record", "Result", "PoundError",
           "InputError", "ParseError", "FileError", "NumericalError", "SolverError",
           "BudgetError", "PoundMemoryError", "LayoutError", "library_path", "version", "plot"]
