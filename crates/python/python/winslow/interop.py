"""Conversion of maps to and from pygismo (G+Smo's Python bindings) and splinepy.

Both packages are optional: they are imported when a conversion is asked for, and a
missing one is an ``ImportError`` saying how to install it. The conversions copy the
knot vectors, degrees, control points (the ``u`` index fastest in all three libraries)
and weights as they are, so a round trip gives the same arrays bit for bit.

- ``to_gismo(map)``: a ``pygismo.nurbs.gsTensorBSpline2``; a ``LayoutSolution``, a
  multipatch ``Document`` or a list of maps: a ``pygismo.core.gsMultiPatch`` (its
  topology computed). pygismo's Python API has no NURBS class: a rational map is refused
  (``Map.write("map.xml")`` writes it for G+Smo's ``gsFileData``).
- ``from_gismo(obj)``: a ``Map`` from a ``gsTensorBSpline2``; a list of ``Map`` from a
  ``gsMultiPatch``.
- ``to_splinepy(map)``: a ``splinepy.BSpline``, or a ``splinepy.NURBS`` when rational.
- ``from_splinepy(obj)``: a ``Map`` from a ``BSpline`` or ``NURBS`` of parametric and
  physical dimension 2.

Maps periodic in ``v`` (ring maps) are refused by the exporters: their periodic basis has
no counterpart in either library's tensor classes.
"""

import importlib

import numpy as np

from ._native import Map


def _require(module, package):
    try:
        return importlib.import_module(module)
    except ImportError as e:
        raise ImportError(f"{module} is not installed: pip install {package}") from e


def _map_of(obj):
    """A ``Map`` of a ``Map`` or ``Solution``."""
    m = getattr(obj, "map", obj)
    if not isinstance(m, Map):
        raise TypeError(f"expected a winslow Map or Solution, got {type(obj).__name__}")
    if any(m.periodic):
        raise ValueError(f"the map {m.name!r} is periodic in v (a ring map): write it as G+Smo XML or JSON instead")
    return m


def _gismo_patch(gs, m):
    if m.weights is not None:
        raise ValueError(
            f"the map {m.name!r} is rational and pygismo's Python API has no gsTensorNurbs2: "
            "write it with Map.write('map.xml') and read that with gsFileData"
        )
    (ku, kv), (pu, pv) = m.knots, m.degrees
    basis = gs.nurbs.gsTensorBSplineBasis2(gs.nurbs.gsKnotVector(ku, pu), gs.nurbs.gsKnotVector(kv, pv))
    return gs.nurbs.gsTensorBSpline2(basis, np.ascontiguousarray(m.control_points))


def to_gismo(obj):
    """A pygismo ``gsTensorBSpline2`` of a map (or ``Solution``); a ``gsMultiPatch`` of a
    ``LayoutSolution``, a multipatch ``Document`` or a list of maps."""
    gs = _require("pygismo", "pygismo")
    maps = None
    if isinstance(obj, (list, tuple)):
        maps = [_map_of(m) for m in obj]
    elif hasattr(obj, "maps"):
        ms = obj.maps() if callable(obj.maps) else obj.maps
        if ms is None:
            raise ValueError(f"the document {obj.name!r} has no patch maps")
        maps = [_map_of(m) for m in ms]
    if maps is None:
        return _gismo_patch(gs, _map_of(obj))
    mp = gs.core.gsMultiPatch()
    for m in maps:
        mp.addPatch(_gismo_patch(gs, m))
    # interfaces where patch corners meet (the patches of a layout conform exactly)
    pts = np.concatenate([m.control_points for m in maps])
    mp.computeTopology(1e-9 * float(np.ptp(pts, 0).max()), False, False)
    return mp


def _from_gismo_patch(p, name=""):
    if p.domainDim() != 2 or p.targetDim() != 2:
        raise ValueError(f"a planar map has 2 parameters and 2 coordinates, got {p.domainDim()} and {p.targetDim()}")
    knots = tuple(np.asarray(p.knots(d).get(), dtype=np.float64) for d in range(2))
    return Map(knots, (p.degree(0), p.degree(1)), np.asarray(p.coefs(), dtype=np.float64), None, name)


def from_gismo(obj):
    """A ``Map`` of a pygismo ``gsTensorBSpline2``; a list of ``Map`` (``patch0``,
    ``patch1``, ...) of a ``gsMultiPatch``."""
    if hasattr(obj, "nPatches"):
        return [_from_gismo_patch(obj.patch(i), f"patch{i}") for i in range(obj.nPatches())]
    if not hasattr(obj, "coefs"):
        raise TypeError(f"expected a pygismo gsTensorBSpline2 or gsMultiPatch, got {type(obj).__name__}")
    return _from_gismo_patch(obj)


def to_splinepy(obj):
    """A ``splinepy.BSpline`` of a map (or ``Solution``), a ``splinepy.NURBS`` when it is
    rational."""
    splinepy = _require("splinepy", "splinepy")
    m = _map_of(obj)
    kw = dict(degrees=list(m.degrees), knot_vectors=[k.tolist() for k in m.knots], control_points=m.control_points)
    if m.weights is None:
        return splinepy.BSpline(**kw)
    return splinepy.NURBS(weights=m.weights.reshape(-1, 1), **kw)


def from_splinepy(obj, name=""):
    """A ``Map`` of a splinepy ``BSpline`` or ``NURBS`` with ``para_dim == dim == 2``."""
    if not hasattr(obj, "knot_vectors"):
        raise TypeError(f"expected a splinepy BSpline or NURBS, got {type(obj).__name__}")
    if obj.para_dim != 2 or obj.dim != 2:
        raise ValueError(f"a planar map has 2 parameters and 2 coordinates, got {obj.para_dim} and {obj.dim}")
    knots = tuple(np.asarray(k, dtype=np.float64) for k in obj.knot_vectors)
    weights = np.asarray(obj.weights, dtype=np.float64).reshape(-1) if obj.is_rational else None
    degrees = tuple(int(d) for d in obj.degrees)
    return Map(knots, degrees, np.asarray(obj.control_points, dtype=np.float64), weights, name)
