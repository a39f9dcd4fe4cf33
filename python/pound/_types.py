"""The type aliases of the public signatures (PEP 484; the package ships
py.typed).  Runtime objects, so typing.get_type_hints resolves them."""
import os
from typing import Sequence, Tuple, Union

import numpy as np
from numpy.typing import ArrayLike

# a file: str, bytes or os.PathLike (a pathlib.Path)
PathArg = Union[str, bytes, os.PathLike]
# an integer argument: Python's or NumPy's (integral floats are accepted too, at run time)
Int = Union[int, np.integer]
# one value, or a sequence of them (the CLI's comma lists)
Floats = Union[float, Sequence[float], np.ndarray]
Names = Union[str, Sequence[str]]
# a range MIN:MAX:N as the CLI's text or a (MIN, MAX, N) tuple
Range = Union[str, Tuple[float, float, int]]

__all__ = ["ArrayLike", "Floats", "Int", "Names", "PathArg", "Range"]
