from typing import Any, Optional, Union

from . import interop as interop
from ._native import (
    SOLVE_OPTIONS as SOLVE_OPTIONS,
    Boundary as Boundary,
    Curve as Curve,
    Document as Document,
    LayoutSolution as LayoutSolution,
    Map as Map,
    Solution as Solution,
    WinslowError as WinslowError,
    __version__ as __version__,
    check as check,
    compare as compare,
    improve as improve,
    layout as layout,
    parse as parse,
    read as read,
    solve as solve,
    solve_many as solve_many,
    sweep as sweep,
    write as write,
)

def mesh(
    map: Union[Map, Solution],
    *,
    structured: Optional[tuple[int, int]] = None,
    size: Optional[float] = None,
    order: int = 1,
    meshio: Optional[bool] = None,
) -> Any:
    """A ``meshio.Mesh`` when meshio is importable, else a dict of arrays."""
