"""Type stubs of the native module of winslow (re-exported by ``winslow``)."""

from os import PathLike
from typing import Any, Callable, Iterable, Optional, Sequence, Union

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
    def to_json(self) -> str: ...
    def to_gismo(self) -> Any:
        """A pygismo ``gsTensorBSpline2`` (``winslow.interop``; needs pygismo)."""
    @staticmethod
    def from_gismo(obj: Any) -> Union[Map, list[Map]]:
        """A ``Map`` of a ``gsTensorBSpline2``, a list of them of a ``gsMultiPatch``."""
    def to_splinepy(self) -> Any:
        """A splinepy ``BSpline`` (``NURBS`` when rational; needs splinepy)."""
    @staticmethod
    def from_splinepy(obj: Any) -> Map:
        """A ``Map`` of a splinepy ``BSpline`` or ``NURBS`` (2 parameters, 2 coordinates)."""

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
    def to_json(self) -> str: ...

class Document:
    """A ring, multipatch layout or result, general domain or volume."""

    @property
    def kind(self) -> str: ...
    @property
    def name(self) -> str: ...
    def maps(self) -> Optional[list[Map]]: ...
    def patches(self) -> Optional[list[Boundary]]:
        """The patches of a layout or multipatch result, each a ``Boundary``."""
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
    def pipeline_seconds(self) -> float: ...
    @property
    def report(self) -> dict[str, Any]: ...
    def write(self, path: Path) -> None: ...
    def to_json(self) -> str: ...

class LayoutSolution:
    """The solved maps of a layout (or of a domain or plane graph laid out)."""

    @property
    def name(self) -> str: ...
    @property
    def verdict(self) -> str: ...
    @property
    def certified(self) -> bool: ...
    @property
    def maps(self) -> list[Map]: ...
    @property
    def report(self) -> dict[str, Any]: ...
    def document(self) -> Document: ...
    def write(self, path: Path) -> None: ...
    def to_json(self) -> str: ...

Input = Union[Boundary, Map, Document, Path]
Progress = Optional[Callable[[dict[str, Any]], Optional[bool]]]

def read(path: Path) -> Union[Map, Boundary, Document]: ...
def parse(text: str) -> Union[Map, Boundary, Document]: ...
def write(path: Path, document: Union[Map, Boundary, Document, Solution]) -> None: ...
def solve(
    input: Input, *, start: Optional[Union[Map, Solution]] = None, progress: Progress = None, **options: Any
) -> Union[Solution, LayoutSolution]:
    """A ``Solution``; a ``LayoutSolution`` of a layout, domain or plane graph. ``start``:
    the previous map of a shape family (``report["warm_start"]`` says if it was used)."""
def solve_many(
    inputs: Iterable[Input],
    *,
    workers: Optional[int] = None,
    on_result: Optional[Callable[[int, Union[Solution, LayoutSolution, WinslowError]], None]] = None,
    same_basis: bool = False,
    warm_start: bool = False,
    **options: Any,
) -> list[Union[Solution, LayoutSolution, WinslowError]]: ...
def layout(domain: Union[Document, Path], **options: Any) -> tuple[Document, dict[str, Any]]:
    """``winslow layout``: the multipatch layout of a domain or plane graph, and its report."""
def improve(
    map: Union[Map, Solution, Path], *, method: str = "winslow", boundary: Optional[Input] = None, **options: Any
) -> Solution:
    """``winslow solve --start MAP --method METHOD``: improved on its own basis, kept when certified."""
def compare(
    boundary: Input,
    methods: Optional[Sequence[str]] = None,
    *,
    lambda1: float = 0.0,
    lambda2: float = 0.0,
    qc_hessian: str = "gauss-newton",
    eps: Optional[float] = None,
    max_sqp: Optional[int] = None,
    max_newton: Optional[int] = None,
    poisson_scales: Optional[tuple[float, float]] = None,
    progress: Progress = None,
    **options: Any,
) -> dict[str, Any]:
    """``winslow compare --json``, each row with its ``map``."""
def sweep(
    ring: Union[Document, Map, Path],
    *,
    rotate_inner: Optional[float] = None,
    steps: Optional[int] = None,
    center: Optional[tuple[float, float]] = None,
    inner_frames: Optional[Sequence[Union[Document, Map, Path]]] = None,
    times: Optional[Sequence[float]] = None,
    seam: str = "slide",
    predictor_order: int = 5,
    progress: Progress = None,
    **options: Any,
) -> list[dict[str, Any]]:
    """``winslow sweep``: one dict per frame, ``map`` and ``report``."""
def solution_from_json(text: str) -> Solution: ...
def check(map: Union[Map, Solution]) -> dict[str, Any]: ...
def mesh_arrays(
    map: Union[Map, Solution], *, structured: Optional[tuple[int, int]] = None, size: Optional[float] = None, order: int = 1
) -> dict[str, Any]: ...
