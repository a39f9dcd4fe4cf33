"""The checks of the binding's arguments, in one place: every keyword and
argument that becomes a C double, int, flag, name, path or array goes
through one of these, so that misuse is refused the same way everywhere
with an InputError naming the argument (as the CLI names the flag):

  number   a finite real (not a bool: True is not 1.0)
  integer  an int or NumPy integer, or an integral float; in C int range
  flag     True/False (also 0/1 and NumPy bools); None is False
  name     a str without NUL, for the library's name parsers
  choice   a str among fixed choices
  path     str, bytes or os.PathLike without NUL: bytes for C, str for messages
  values   a value or a sequence of values, element types kept
  real_array  a NumPy float64 array of finite real numbers (not bools, strings,
              complex numbers; a masked array only with nothing masked)

A value refused is shown as the CLI shows a flag's text ('%s'), or as its
repr when that text has control characters (a NUL) in it."""
import math
import numbers
import os

import numpy as np

from ._lib import InputError

INT_MIN, INT_MAX = -2 ** 31, 2 ** 31 - 1


def show(value):
    """A refused value in a message: '...' around its text (repr when the
    text is not printable)."""
    text = "%s" % (value,)
    return "'%s'" % text if text.isprintable() else repr(text)


def _head(what, part):
    return "%s: %s " % (what, part) if part else "%s: " % what


def is_bool(value):
    return isinstance(value, (bool, np.bool_)) or \
        (isinstance(value, np.ndarray) and value.dtype.kind == "b")


def number(what, value, part=None):
    """value as a finite float (as float(value): the same double)."""
    if is_bool(value):
        raise InputError("%s%s is a bool, not a number" % (_head(what, part), show(value)))
    try:
        x = float(value)
    except (TypeError, ValueError):
        raise InputError("%s%s is not a number" % (_head(what, part), show(value))) from None
    if not math.isfinite(x):
        raise InputError("%s%s is not a finite number" % (_head(what, part), show(value)))
    return x


def integer(what, value, part=None):
    """value as an int: ints and NumPy integers, integral floats, decimal
    strings (the CLI's text); not bools, not fractions; in C int range."""
    if is_bool(value):
        raise InputError("%s%s is a bool, not an integer" % (_head(what, part), show(value)))
    x = None
    if isinstance(value, (int, np.integer)):
        x = int(value)
    elif isinstance(value, (float, np.floating)):
        if math.isfinite(value) and float(value).is_integer():
            x = int(value)
    elif isinstance(value, str):
        try:
            x = int(value, 10)
        except ValueError:
            pass
    if x is None:
        raise InputError("%s%s is not an integer" % (_head(what, part), show(value)))
    if not INT_MIN <= x <= INT_MAX:
        raise InputError("%s%s is out of range (at most %d)"
                         % (_head(what, part), show(value), INT_MAX))
    return x


def flag(what, value):
    """A switch: True/False, 0/1 (NumPy's too); None (not given) is False."""
    if value is None:
        return False
    if is_bool(value) and np.ndim(value) == 0:
        return bool(value)
    if isinstance(value, (int, np.integer)) and value in (0, 1):
        return bool(value)
    raise InputError("%s: expected True or False (got %s)" % (what, show(value)))


def name(what, value, choices):
    """A str for the library's name parsers, as bytes (a NUL would end it
    early in C: 'sine\\0x' read as 'sine')."""
    if not isinstance(value, str) or "\0" in value:
        raise InputError("%s: %s is not one of %s" % (what, show(value), choices))
    return value.encode()


def choice(what, value, choices):
    """One of the str choices (a sequence or a dict's keys)."""
    if not isinstance(value, str) or value not in choices:
        raise InputError("%s: %s is not one of %s" % (what, show(value), ", ".join(choices)))
    return value


def path(what, value):
    """(bytes for the C call, str for messages) of a str, bytes or
    os.PathLike path, as os.fsencode and os.fsdecode make them."""
    try:
        p = os.fspath(value)
    except TypeError:
        raise InputError("%s: expected a path (str, bytes or os.PathLike), got %s"
                         % (what, type(value).__name__)) from None
    text = os.fsdecode(p)
    if not text:
        raise InputError("%s: the path is empty" % what)
    if "\0" in text:
        raise InputError("%s: the path %r contains a NUL character" % (what, text))
    return os.fsencode(p), text


def values(what, value, cap=None):
    """A value or a sequence of them as a list, the elements as given (a
    list is not made an array: [0.5, True] keeps its bool)."""
    if isinstance(value, np.ndarray):
        vals = value.reshape(-1).tolist()
    elif isinstance(value, (str, bytes)) or not hasattr(value, "__iter__"):
        vals = [value]
    else:
        vals = list(value)
    if not vals:
        raise InputError("%s: empty list" % what)
    if cap is not None and len(vals) > cap:
        raise InputError("%s: at most %d values" % (what, cap))
    return vals


def _kind(x):
    """What an entry that is not a real number is, for a message."""
    if x is None:
        return "None"
    if is_bool(x):
        return "a bool (%s)" % show(x)
    if isinstance(x, (str, bytes)):
        return "a string (%r)" % (x,)
    if isinstance(x, (complex, np.complexfloating)):
        return "complex (%s)" % show(x)
    return "a %s" % type(x).__name__


def _entry(a, k):
    """The index k of the flattened a as the message names it."""
    index = np.unravel_index(k, a.shape) if a.ndim else ()
    return str(int(index[0])) if len(index) == 1 else str(tuple(int(i) for i in index))


def _real_entries(what, a):
    """Refuse the first entry of the object array a that is not a real
    number: a bool, a string, a complex, None, a sequence (a ragged list)."""
    flat = a.reshape(-1)
    types = {type(x) for x in flat.tolist()}
    if all(issubclass(t, numbers.Real) and not issubclass(t, (bool, np.bool_)) for t in types):
        return
    for k, x in enumerate(flat.tolist()):
        if not isinstance(x, numbers.Real) or is_bool(x):
            if a.ndim == 0:
                raise InputError("%s: not a real number or an array of them (%s)"
                                 % (what, _kind(x)))
            raise InputError("%s: not an array of real numbers (entry %s is %s)"
                             % (what, _entry(a, k), _kind(x)))


def real_array(what, value, finite=True):
    """A float64 array of value (the same doubles as np.asarray(value,
    np.float64)): real numbers, every entry finite (unless not finite); the
    first one that is not named by its index.  Real means int or float
    entries (NumPy's too): bools, strings, complex numbers (whose imaginary
    part a conversion drops), dates and None are refused, in an array's
    dtype as in a list's entries.  A masked array (numpy.ma) is taken when
    no entry is masked (its data; a mask is never ignored), else refused
    naming the first masked entry."""
    if np.ma.isMaskedArray(value):
        mask = np.ma.getmaskarray(value)
        if mask.any():
            k = int(np.flatnonzero(mask.reshape(-1))[0])
            raise InputError("%s: entry %s is masked (a masked array is taken only with no "
                             "entry masked: fill or drop the masked entries)"
                             % (what, _entry(mask, k)))
        value = np.ma.getdata(value)
    try:
        # a list's entries as given (np.asarray would make [0.5, True] floats)
        a = np.asarray(value) if hasattr(value, "dtype") else np.asarray(value, dtype=object)
    except (TypeError, ValueError):
        raise InputError("%s: not an array of real numbers" % what) from None
    kind = a.dtype.kind
    if kind == "b":
        raise InputError("%s: the entries are bools, not numbers" % what)
    if kind == "c":
        raise InputError("%s: the entries are complex, not real numbers (refused, not "
                         "their imaginary parts dropped)" % what)
    if kind in "US":
        raise InputError("%s: the entries are strings, not numbers" % what)
    if kind == "O":
        _real_entries(what, a)
    elif kind not in "iuf":
        raise InputError("%s: the entries are %s, not real numbers" % (what, a.dtype))
    try:
        a = np.asarray(a, dtype=np.float64)
    except (TypeError, ValueError, OverflowError):
        raise InputError("%s: not an array of real numbers" % what) from None
    if not finite:
        return a
    if a.ndim == 0 and not np.isfinite(a):
        raise InputError("%s: %s is not a finite number" % (what, show(value)))
    bad = np.argwhere(~np.isfinite(a))
    if len(bad):
        index = tuple(int(i) for i in bad[0])
        raise InputError("%s: entry %s is not finite"
                         % (what, index[0] if len(index) == 1 else str(index)))
    return a


def nonfinite_at(what, vals, where):
    """Refuse the first non-finite entry of vals (1-D), named where(k)."""
    bad = np.flatnonzero(~np.isfinite(vals))
    if len(bad):
        raise InputError("%s: entry %s is not finite" % (what, where(int(bad[0]))))
