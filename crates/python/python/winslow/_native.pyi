"""Type stubs of the native module of winslow (re-exported by ``winslow``)."""

from os import PathLike
from typing import Any, Callable, Optional, Sequence, Union

import numpy as np
import numpy.typing as npt

__version__: str
SOLVE_OPTIONS: list[str]

ArrayLike = npt.ArrayLike
Path = Union[str, PathLike[str]]

class WinslowError(Exception):
    """An error of winslow: ``kind`` names the typed error, ``message`` is its text."""

    kind: str
    message: str

class Map:
    """A planar tensor-product B-spline or NURBS map of the unit square."""

    def __init__(
        self,
        knots: tuple[ArrayLike, ArrayLike],
        degrees: tuple[int, int],
        control_points: ArrayLike,
        weights: Optional[ArrayLike] = None,
        name: str = "",
    ) -> None: ...
    @property
    def name(self) -> str: ...
    @property
    def degrees(self) -> tuple[int, int]: ...
    @property
    def shape(self) -> tuple[int, int]: ...
    @property
    def periodic(self) -> tuple[bool, bool]: ...
    @property
    def knots(self) -> tuple[np.ndarray, np.ndarray]: ...
    @property
    def control_points(self) -> np.ndarray: ...
    @property
    def weights(self) -> Optional[np.ndarray]: ...
    def evaluate(self, u: ArrayLike, v: ArrayLike) -> np.ndarray:
        """``x(u, v)``: shape ``S + (2,)`` for parameters of shape ``S``."""
    def jacobian(self, u: ArrayLike, v: ArrayLike) -> np.ndarray:
        """``J[..., i, j] = d x_i / d u_j``: shape ``S + (2, 2)``."""
    def det_j(self, u: ArrayLike, v: ArrayLike) -> np.ndarray:
        """``det J``: shape ``S``."""
    def boundary(self) -> Boundary: ...
    def write(self, path: Path) -> None: ...

class Curve:
    """A planar B-spline or NURBS curve."""

    def __init__(
        self, knots: ArrayLike, degree: int, control_points: ArrayLike, weights: Optional[ArrayLike] = None
    ) -> None: ...
    @property
    def degree(self) -> int: ...
    @property
    def knots(self) -> np.ndarray: ...
    @property
    def control_points(self) -> np.ndarray: ...
    @property
    def weights(self) -> Optional[np.ndarray]: ...
    def evaluate(self, t: ArrayLike) -> np.ndarray: ...

class Boundary:
    """Four sides (south, east, north, west), each a ``Curve`` or an ``(n, 2)`` array."""

    def __init__(self, sides: Sequence[Union[Curve, ArrayLike]], name: str = "") -> None: ...
    @property
    def name(self) -> str: ...
    @property
    def sides(self) -> list[Union[Curve, np.ndarray]]: ...
    def write(self, path: Path) -> None: ...

class Document:
    """A ring, multipatch layout or result, general domain or volume."""

    @property
    def kind(self) -> str: ...
    @property
    def name(self) -> str: ...
    def maps(self) -> Optional[list[Map]]: ...
    def write(self, path: Path) -> None: ...

class Solution:
    """A solved map with its report."""

    @property
    def name(self) -> str: ...
    @property
    def map(self) -> Map: ...
    @property
    def verdict(self) -> str: ...
    @property
    def certified(self) -> bool: ...
    @property
    def report(self) -> dict[str, Any]: ...
    def write(self, path: Path) -> None: ...

Input = Union[Boundary, Map, Document, Path]

def read(path: Path) -> Union[Map, Boundary, Document]: ...
def parse(text: str) -> Union[Map, Boundary, Document]: ...
def write(path: Path, document: Union[Map, Boundary, Document, Solution]) -> None: ...
def solve(
    input: Input, *, progress: Optional[Callable[[dict[str, Any]], Optional[bool]]] = None, **options: Any
) -> Solution: ...
def solve_many(
    inputs: Sequence[Input],
    *,
    workers: Optional[int] = None,
    on_result: Optional[Callable[[int, Union[Solution, WinslowError]], None]] = None,
    **options: Any,
) -> list[Union[Solution, WinslowError]]: ...
def check(map: Union[Map, Solution]) -> dict[str, Any]: ...
def mesh_arrays(
    map: Union[Map, Solution], *, structured: Optional[tuple[int, int]] = None, size: Optional[float] = None, order: int = 1
) -> dict[str, Any]: ...
