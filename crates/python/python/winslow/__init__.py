"""winslow: certified spline maps of planar domains by elliptic grid generation.

Documents are objects whose knots, control points and weights are numpy arrays
(``Map``, ``Curve``, ``Boundary``, ``Document``); ``read``/``write`` handle every format
of the command line (JSON, G+Smo XML, IGES, VTK); ``solve`` runs the pipeline of
``winslow solve`` with the GIL released; ``solve_many`` solves many shapes on a thread
pool; ``check`` is the certificate of ``winslow check``; ``mesh`` returns arrays, or a
``meshio.Mesh`` when meshio is installed; ``improve``, ``compare``, ``sweep`` and
``layout`` are the runs of the commands of those names; ``solve(boundary,
start=previous)`` and ``solve_many(..., warm_start=True)`` solve a shape family from the
previous map. ``Map.to_gismo``/``from_gismo`` and ``to_splinepy``/``from_splinepy``
convert to pygismo and splinepy objects when those are installed. Errors are
``WinslowError`` with ``kind`` and ``message``. The guide: docs/python.md.
"""

from ._native import (  # noqa: F401
    SOLVE_OPTIONS,
    Boundary,
    Curve,
    Document,
    LayoutSolution,
    Map,
    Solution,
    WinslowError,
    __version__,
    check,
    compare,
    improve,
    layout,
    parse,
    read,
    solve,
    solve_many,
    sweep,
    write,
)
from . import interop  # noqa: F401
from ._native import mesh_arrays as _mesh_arrays

__all__ = [
    "SOLVE_OPTIONS",
    "Boundary",
    "Curve",
    "Document",
    "LayoutSolution",
    "Map",
    "Solution",
    "WinslowError",
    "__version__",
    "check",
    "compare",
    "improve",
    "interop",
    "layout",
    "mesh",
    "parse",
    "read",
    "solve",
    "solve_many",
    "sweep",
    "write",
]


def mesh(map, *, structured=None, size=None, order=1, meshio=None):
    """A mesh of ``map`` (a ``Map`` or ``Solution``), as ``winslow mesh`` makes it.

    ``structured=(nx, ny)`` points per direction, or ``size=h`` for an unstructured
    triangulation (elements of order ``order``). Returns a ``meshio.Mesh`` when meshio
    is importable (and ``meshio`` is not ``False``), else a dict of arrays ``points``
    ``(n, 2)``, ``params`` ``(n, 2)``, ``cells`` ``(m, k)``, ``cell_type`` and ``order``.
    ``meshio=True`` requires meshio.
    """
    arrays = _mesh_arrays(map, structured=structured, size=size, order=order)
    if meshio is False:
        return arrays
    try:
        import meshio as _meshio
    except ImportError:
        if meshio:
            raise
        return arrays
    return _meshio.Mesh(arrays["points"], [(arrays["cell_type"], arrays["cells"])],
                        point_data={"params": arrays["params"]})
