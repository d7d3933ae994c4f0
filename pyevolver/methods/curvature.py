"""Squared mean curvature energies and ∫H dA as quantity methods (spec §5).

Every vertex method is built from three sums over the star of facets of a
vertex v (Surface Evolver manual, "Named methods"; spec §5 checked against
evolver-nox-d 2.70):

* ``A_v = Σ_f A_f`` — the whole star area;
* ``F_v = ∇_v A`` — the area gradient at v, ``Σ_f ½ n_f × e_f`` (e_f the side
  of f opposite v);
* ``N_v = Σ_f ½ N_f`` — the facets' area vectors.

with the mean curvature estimates ``h_plain = 3|F|/(2A)``,
``h_eff = 3|F|/(2|N|)``, ``h_norm = 3 F·F/(2 F·N)``, ``h_perp = 3 F·N/(2 N·N)``
and ``E_v = (h − h0)² A/3``.  The gradient of ``Σ_v E_v`` with respect to
all vertices follows by the chain rule: ``∂E/∂F`` is carried to the
vertices by the facet-area Hessian (applied facet by facet as a
Hessian-vector product, never assembled), ``∂E/∂N`` through
``∂(D·N_f)/∂x`` and ``∂E/∂A`` through the area gradient.

``mean_curvature_integral`` is the edge method ``Σ_e ½ L_e θ_e`` with θ_e
the signed exterior dihedral angle (positive where the surface is convex
towards its normals), ∫H dA with H = (k1 + k2)/2.

At vertices on level-set constraints F and N are projected onto the
constraints' tangent space (the constraints act as mirror planes; manual,
"eff_area_sq_mean_curvature"), by REF's rules found by experiment
(:func:`mirror_projector`, docs/supported.md); a vertex on a free edge off
any constraint uses its partial star as it is.
"""
from __future__ import annotations

import numpy as np

from ..constraints.levelset import curved_constraints, tangent_projectors
from ..errors import UnsupportedError
from ..model.records import edge_facets
from ._common import corner_scatter, facet_points, finite, n2_grad_dot, scatter
from ..geometry.kernels import cross
from .basic import facet_area_grad
from . import axis_major as AM

# method -> (estimate, honours h_zero, old-style (zero at FIXED / boundary vertices))
VERTEX_METHODS = {
    "sq_mean_curvature": ("plain", "switch", True),
    "eff_area_sq_mean_curvature": ("eff", "switch", True),
    "normal_sq_mean_curvature": ("norm", "yes", True),
    "star_sq_mean_curvature": ("plain", "no", False),
    "star_eff_area_sq_mean_curvature": ("eff", "no", False),
    "star_normal_sq_mean_curvature": ("norm", "yes", False),
    "star_perp_sq_mean_curvature": ("perp", "yes", False),
}


def _scatter(nv, idx, vals):
    """Sum rows ``vals`` (k, 3) or values (k,) into the vertices ``idx``."""
    if vals.ndim == 1:
        return np.bincount(idx, weights=vals, minlength=nv)
    return np.stack([np.bincount(idx, weights=vals[:, k], minlength=nv) for k in range(3)], 1)


def vertex_weights(nv, idx, w):
    """Per-vertex weights (nv,): ``w`` summed into the vertices ``idx``."""
    wv = np.zeros(nv)
    np.add.at(wv, np.asarray(idx, np.int64), np.asarray(w, float))
    return wv


_C1 = np.array([1, 2, 0])         # (c + 1) % 3
_C2 = np.array([2, 0, 1])         # (c + 2) % 3


def star_sums(t):
    """Per-vertex star area ``A`` (nv,), area gradient ``F`` (nv, 3) and sum
    of area vectors ``N`` (nv, 3), from the corners the :class:`Totals`
    gathered axis-major (cross products by components, bincount scatters:
    this runs in every trial move of ``g``)."""
    s = t.surface
    nv = s.nv
    Fc = s.facet_corners()                                   # (3 corners, nf)
    Pc = getattr(t, "_corner_xyz", None)                     # gathered by Totals
    if Pc is not None:
        P = Pc                                               # P[axis][corner] (nf,)
        N2 = t.facet_N2.T
    elif s.periods is not None:
        # the torus: each facet's corners unwrapped by its edges' wraps, so
        # a star across the periodic wrap sees its true neighbours
        P = facet_points(t).transpose(2, 1, 0)
        N2 = t.facet_N2.T
    else:
        P = np.ascontiguousarray(s.X.T)[:, Fc]               # (3 axes, 3 corners, nf)
        a = P[:, 1] - P[:, 0]
        b = P[:, 2] - P[:, 0]
        N2 = np.stack([a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2],
                       a[0] * b[1] - a[1] * b[0]])           # (3, nf)
    L = 2.0 * t.facet_area
    with np.errstate(all="ignore"):
        n = finite(N2 / L)
    idx4, idxc = _star_index(s, Fc)
    # A and the three axes of N in one bincount (each its own bins, summed in
    # the corners' order as one bincount per axis would)
    W4 = np.empty((4, 3, len(L)))
    W4[0] = L
    W4[1:] = np.asarray(N2)[:, None, :]
    AN = np.bincount(idx4, weights=W4.ravel(), minlength=4 * nv).reshape(4, nv)
    AN = AN.astype(np.float64, copy=False)      # (numpy's bincount of no weights is int64)
    AN *= 0.5
    A = AN[0]
    N = np.ascontiguousarray(AN[1:].T)
    # the side opposite each corner c, e[axis][c] = P[axis][c+2] - P[axis][c+1],
    # and 0.5 n x e for the three corners at once (W[axis][c]); F sums the
    # corners' scatters in the corner order, (c0 + c1) + c2, the axes together
    P = np.asarray(P)
    e = P.take(_C2, axis=1) - P.take(_C1, axis=1)
    W = n.take(_C1, axis=0)[:, None, :] * e.take(_C2, axis=0)
    W -= n.take(_C2, axis=0)[:, None, :] * e.take(_C1, axis=0)
    W *= 0.5
    F3 = np.bincount(idxc[0], weights=W[:, 0].ravel(), minlength=3 * nv)
    F3 = F3.astype(np.float64, copy=False)
    F3 += np.bincount(idxc[1], weights=W[:, 1].ravel(), minlength=3 * nv)
    F3 += np.bincount(idxc[2], weights=W[:, 2].ravel(), minlength=3 * nv)
    F = np.ascontiguousarray(F3.reshape(3, nv).T)
    return A, F, N


def _star_index(s, Fc):
    """Bincount indices of :func:`star_sums` (kept with the corners ``Fc``):
    the corners, corner-major, for four quantities, and each corner's for
    three axes."""
    c = s.__dict__.get("_star_index")
    if c is not None and c[0] is Fc:
        return c[1], c[2]
    nv = s.nv
    flat = Fc.ravel()
    idx4 = np.concatenate([flat + j * nv for j in range(4)])
    idxc = [np.concatenate([Fc[k] + j * nv for j in range(3)]) for k in range(3)]
    s._star_index = (Fc, idx4, idxc)
    return idx4, idxc


def _h_zero(s, method):
    """Per-vertex h0 (nv,) or None when h_zero is not defined."""
    ex = s.extra.get(("vertex", "h_zero"))
    if ex is not None:
        return np.asarray(ex, float).reshape(s.nv)
    if "h_zero" in s.params:
        return np.full(s.nv, float(s.params["h_zero"]))
    return None


def _check_supported(s, what=None):
    """Refuse ``what`` (a method reading ``s.X`` directly, not the unwrapped
    facet corners) in the torus model; the star methods built on
    :func:`star_sums` / :func:`facet_points` work across the wrap."""
    if what is not None and s.periods is not None:
        raise UnsupportedError(f"{what} in the torus model")


def _check_closed(s, what, constraints=False):
    """Refuse ``what`` on surfaces with a free edge and, unless ``constraints``
    (REF evaluates it there without projection), at constrained vertices."""
    _check_supported(s)
    if not constraints and s.vcon and any(np.any(m) for m in s.vcon.values()):
        raise UnsupportedError(f"{what} at vertices on level-set constraints",
                               "no mirror rule known")
    if _edge_valence_one_vertices(s).any():
        raise UnsupportedError(f"{what} on surfaces with a free boundary",
                               "the partial stars of boundary vertices")


def _edge_valence_one_vertices(s):
    """(nv,) bool: the vertices on an edge with exactly one facet (cached per topology)."""
    topo = s.topology()
    c = s.__dict__.get("_free_boundary")
    if c is None or c[0] is not topo:
        ev = np.bincount(topo[0].ravel(), minlength=s.ne) == 1
        on = np.zeros(s.nv, bool)
        on[s.E[ev].ravel()] = True
        c = (topo, on)
        s._free_boundary = c
    return c[1]


def _wall_vertices(s, nonwall):
    """(nv,) bool: vertices on a level-set constraint that acts as a mirror
    (NONWALL ones too when ``nonwall``)."""
    on = np.zeros(s.nv, bool)
    for cid, mask in (s.vcon or {}).items():
        if nonwall or "nonwall" not in s.constraints[cid].flags:
            on |= np.asarray(mask, bool)
    return on


def mirror_projector(s, m):
    """The vertices whose ``F`` and ``N`` REF projects onto their constraints'
    tangent space (the constraints as mirror planes) and the projectors there.

    Old-style methods (``sq_mean_curvature``, ``eff_area_…``, ``normal_…``) project
    at every vertex on a level-set constraint; the ``star_…`` methods only at
    those that also lie on an edge with one facet (an incomplete star).
    ``ignore_constraints`` in the declaration turns it off for the old
    methods only (REF: no effect on the star methods).  Measured against
    evolver-nox-d 2.70 on a mound (free edge on z = 0) and a closed cube with
    its bottom vertices on z = 0 (docs/supported.md).

    Returns
    -------
    rows : (k,) int
        The projected vertices (empty: none).
    P : (k, 3, 3)
        ``I − G (GᵀG)⁻¹ Gᵀ`` of each, G the gradients of its constraints.
    """
    empty = (np.zeros(0, np.int64), np.zeros((0, 3, 3)))
    old = VERTEX_METHODS.get(m.method, ("", "", True))[2]
    if not s.vcon or (old and getattr(m, "ignore_constraints", False)):
        return empty
    on = _wall_vertices(s, old)
    if not old:
        on &= _edge_valence_one_vertices(s)
    rows = np.nonzero(on)[0]
    if not len(rows):
        return empty
    return rows, tangent_projectors(s, rows, nonwall=old)


def check_old_gradient(s, m, rows):
    """Refuse the gradient of an old-style method where REF's force is not the
    derivative of its energy (measured with ``v_force`` after ``g 1``): at
    vertices on curved constraints; for the h_zero, ``eff_area`` and
    ``normal`` estimates also at unskipped vertices on a free edge that are not
    projected, at projected ones with a complete star (``eff``/``normal``) and
    at any projected one (with h_zero).  ``sq_mean_curvature`` without
    h_zero agrees with REF on free edges and plane constraints."""
    kind0, _, old = VERTEX_METHODS.get(m.method, ("plain", "no", True))
    if not old:
        return
    if len(rows):
        curved = curved_constraints(s, rows)
        if curved:
            raise UnsupportedError(
                f"the gradient of {m.method} at vertices on curved constraints ({curved[0]})",
                "REF's force there is neither the derivative with the projector held "
                "constant nor the exact one; the star_ methods are supported")
    kind, h0, _ = _kind(s, m.method)
    if kind == "plain" and h0 is None:
        return
    live = ~_skipped(s, m)
    proj = np.zeros(s.nv, bool)
    proj[rows] = True
    edge = _edge_valence_one_vertices(s)
    bad = live & edge & ~proj
    bad |= live & proj & (~edge if h0 is None else True)
    if bad.any():
        what = "h_zero" if h0 is not None else kind0
        raise UnsupportedError(
            f"the gradient of {m.method} ({what}) at vertices on a free edge or a constraint",
            "REF's force there is not the derivative of its energy; use the star_ methods")


def _project(rows, P, v):
    """``v`` (nv, 3) with the rows ``rows`` multiplied by their projectors."""
    if not len(rows):
        return v
    v = v.copy()
    v[rows] = np.einsum("nij,nj->ni", P, v[rows])
    return v


def _kind(s, name):
    """The estimate a method uses on this surface, its h0 (nv,) or None,
    and whether it is old-style."""
    kind, hz, old = VERTEX_METHODS[name]
    h0 = _h_zero(s, name) if hz != "no" else None
    if h0 is not None and hz == "switch":
        kind = "perp"                      # REF: defining h_zero switches to h_perp
    return kind, h0, old


def _skipped(s, m=None):
    """(nv,) bool: vertices where the old-style methods are zero (FIXED ones
    unless the declaration says ``ignore_fixed``, parametric-boundary ones)."""
    skip = np.zeros(s.nv, bool) if getattr(m, "ignore_fixed", False) else s.vattr["fixed"].copy()
    if "boundary" in s.vattr:
        skip |= s.vattr["boundary"] != 0
    return skip


def _energy_only(s, A, FF, FN, NN, kind, h0, old, m):
    """The ``E`` of :func:`_vertex_energy`, by the same operations, without
    the derivatives (the trial moves of ``g`` evaluate energies only)."""
    with np.errstate(all="ignore"):
        if kind == "plain":
            E = 0.75 * FF / A
        elif kind == "eff":
            E = 0.75 * A * FF / NN
        else:
            if kind == "norm":
                ok = FN != 0
                h = np.where(ok, 1.5 * FF / FN, 0.0)
            else:                               # perp
                ok = NN > 0
                h = np.where(ok, 1.5 * FN / NN, 0.0)
            d = h - (h0 if h0 is not None else 0.0)
            E = d * d * A / 3.0
    E = finite(np.asarray(E, float))
    if old:
        E[_skipped(s, m)] = 0.0
    return E


def _vertex_energy(s, A, F, N, name, m=None, derivatives=True):
    """``E`` (nv,) and its partial derivatives ``dF``, ``dN`` (nv, 3), ``dA``
    (without ``derivatives``: ``E`` and three Nones)."""
    kind, h0, old = _kind(s, name)
    nv = s.nv
    FF = np.einsum("ij,ij->i", F, F)
    FN = np.einsum("ij,ij->i", F, N)
    NN = np.einsum("ij,ij->i", N, N)
    if not derivatives:
        return _energy_only(s, A, FF, FN, NN, kind, h0, old, m), None, None, None
    dF = np.zeros((nv, 3))
    dN = np.zeros((nv, 3))
    with np.errstate(all="ignore"):
        if kind == "plain":
            E = 0.75 * FF / A
            dF = 1.5 * F / A[:, None]
            dA = -0.75 * FF / A ** 2
        elif kind == "eff":
            E = 0.75 * A * FF / NN
            dF = 1.5 * (A / NN)[:, None] * F
            dN = -1.5 * (A * FF / NN ** 2)[:, None] * N
            dA = 0.75 * FF / NN
        else:
            if kind == "norm":
                ok = FN != 0
                h = np.where(ok, 1.5 * FF / FN, 0.0)
                dhF = np.where(ok[:, None], 1.5 * (2 * F * FN[:, None] - FF[:, None] * N)
                               / (FN ** 2)[:, None], 0.0)
                dhN = np.where(ok[:, None], -1.5 * (FF / FN ** 2)[:, None] * F, 0.0)
            else:                               # perp
                ok = NN > 0
                h = np.where(ok, 1.5 * FN / NN, 0.0)
                dhF = np.where(ok[:, None], 1.5 * N / NN[:, None], 0.0)
                dhN = np.where(ok[:, None], 1.5 * (F * NN[:, None] - 2 * FN[:, None] * N)
                               / (NN ** 2)[:, None], 0.0)
            d = h - (h0 if h0 is not None else 0.0)
            E = d * d * A / 3.0
            dF = (2 * d * A / 3.0)[:, None] * dhF
            dN = (2 * d * A / 3.0)[:, None] * dhN
            dA = d * d / 3.0
    E, dA = finite(np.asarray(E, float)), finite(np.asarray(dA, float))
    dF, dN = finite(dF), finite(dN)
    if old:
        skip = _skipped(s, m)
        E[skip] = 0.0
        dF[skip] = 0.0
        dN[skip] = 0.0
        dA[skip] = 0.0
    return E, dF, dN, dA


def vertex_values(ctx, m, idx):
    """Per-vertex energies of a squared mean curvature method."""
    s = ctx.surface
    _check_supported(s)
    A, F, N = star_sums(ctx)
    rows, P = mirror_projector(s, m)
    F, N = _project(rows, P, F), _project(rows, P, N)
    E, _, _, _ = _vertex_energy(s, A, F, N, m.method, m, derivatives=False)
    return E[idx]


def _area_hvp(P, n, L, U):
    """Facet-area Hessian times per-corner vectors ``U`` (nf, 3, 3), facet
    by facet: the directional derivative of ``∂A/∂x_a = ½ n × e_a``."""
    e = np.stack([P[:, 2] - P[:, 1], P[:, 0] - P[:, 2], P[:, 1] - P[:, 0]], 1)
    de = np.stack([U[:, 2] - U[:, 1], U[:, 0] - U[:, 2], U[:, 1] - U[:, 0]], 1)
    dN2 = (cross(U[:, 1] - U[:, 0], P[:, 2] - P[:, 0])
           + cross(P[:, 1] - P[:, 0], U[:, 2] - U[:, 0]))
    with np.errstate(all="ignore"):
        dn = finite((dN2 - n * np.einsum("ij,ij->i", n, dN2)[:, None]) / L[:, None])
    return 0.5 * (cross(dn[:, None, :], e) + cross(n[:, None, :], de))


def vertex_gradient(t, m, idx, w):
    """Gradient (nv, 3) of ``Σ_v w_v E_v`` over the vertices ``idx``."""
    s = t.surface
    _check_supported(s)
    A, F, N = star_sums(t)
    rows, Pm = mirror_projector(s, m)
    check_old_gradient(s, m, rows)
    F, N = _project(rows, Pm, F), _project(rows, Pm, N)
    _, dF, dN, dA = _vertex_energy(s, A, F, N, m.method, m)
    dF, dN = _project(rows, Pm, dF), _project(rows, Pm, dN)   # projectors held constant
    if AM.available(t):                 # (the same numbers, fewer numpy calls)
        wv = vertex_weights(s.nv, idx, w)
        return AM.scatter(s, AM.star_perp_chain(t, dF * wv[:, None], dN * wv[:, None], dA * wv))
    P = facet_points(t)
    L = 2.0 * t.facet_area
    with np.errstate(all="ignore"):
        n = finite(t.facet_N2 / L[:, None])
    Ag = facet_area_grad(t)
    wv = vertex_weights(s.nv, idx, w)
    dF, dN, dA = dF * wv[:, None], dN * wv[:, None], dA * wv
    Fc = s.F
    g = _area_hvp(P, n, L, dF[Fc])                                # via F_v
    g += 0.5 * n2_grad_dot(P, dN[Fc].sum(axis=1))              # via N_v
    g += Ag * dA[Fc].sum(axis=1)[:, None, None]                    # via A_v
    return corner_scatter(t, g)


# -- mean_curvature_integral ----------------------------------------------------------------

def _dihedral(t, idx):
    """For the edges ``idx``: which have two facets (``ok``), those edges
    ``e``, and their facets running along (``f1``) and against (``f2``) them."""
    s = t.surface
    ef, ek, val = edge_facets(s)
    ok = val[idx] == 2
    e = idx[ok]
    fa, fb = ef[e, 0], ef[e, 1]
    ka = ek[e, 0]
    fwd_a = s.FE[fa, ka] >= 0
    f1 = np.where(fwd_a, fa, fb)
    f2 = np.where(fwd_a, fb, fa)
    return ok, e, f1, f2


def mci_values(ctx, m, idx):
    s = ctx.surface
    if s.periods is not None:
        raise UnsupportedError("mean_curvature_integral in the torus model")
    idx = np.asarray(idx, np.int64)
    out = np.zeros(len(idx))
    ok, e, f1, f2 = _dihedral(ctx, idx)
    N1, N2 = ctx.facet_N2[f1], ctx.facet_N2[f2]
    d = ctx.edge_vec[e]
    Le = np.linalg.norm(d, axis=1)
    S = np.einsum("ij,ij->i", np.cross(N1, N2), d) / Le
    C = np.einsum("ij,ij->i", N1, N2)
    if m.method == "mean_curvature_integral_a":
        with np.errstate(all="ignore"):
            out[ok] = 0.5 * Le * S / C          # REF's "_a": ½ L tan θ (blob0: 1e-15)
    else:
        out[ok] = 0.5 * Le * np.arctan2(S, C)
    return out


def mci_gradient(t, m, idx, w):
    s = t.surface
    idx = np.asarray(idx, np.int64)
    ok, e, f1, f2 = _dihedral(t, idx)
    w = np.asarray(w, float)[ok]
    P = facet_points(t)
    P1, P2 = P[f1], P[f2]
    N1, N2 = t.facet_N2[f1], t.facet_N2[f2]
    d = t.edge_vec[e]
    Le = np.linalg.norm(d, axis=1)
    u = d / Le[:, None]
    X = np.cross(N1, N2)
    S = np.einsum("ij,ij->i", X, u)
    C = np.einsum("ij,ij->i", N1, N2)
    theta = np.arctan2(S, C)
    R = S * S + C * C
    # dθ = (C dS − S dC)/R with S = u·(N1 × N2), C = N1·N2; REF drops dθ at
    # exactly flat edges (its acos form is singular there: cube.fe's faces);
    # at edges flat only to round-off (a refined curved surface) what REF
    # does depends on its rounding, and the exact dθ is kept
    flat = S == 0.0
    if m.method == "mean_curvature_integral_a":       # ½ L tan θ: d tan θ = (C dS − S dC)/C²
        flat[:] = False
        with np.errstate(all="ignore"):
            theta = S / C
            R = C * C
    a = np.where(flat, 0.0, C / R)[:, None]
    b = np.where(flat, 0.0, S / R)[:, None]
    # through N1 (facet f1 corners) and N2 (facet f2 corners)
    g1 = n2_grad_dot(P1, a * np.cross(N2, u) - b * N2)
    g2 = n2_grad_dot(P2, a * np.cross(u, N1) - b * N1)
    # through u = d/|d| (edge endpoints)
    du = a * X
    du = (du - u * np.einsum("ij,ij->i", u, du)[:, None]) / Le[:, None]
    coef = (0.5 * Le * w)[:, None, None]
    g = np.zeros((s.nv, 3))
    g += scatter(s.nv, s.F[f1].ravel(), (g1 * coef).reshape(-1, 3))
    g += scatter(s.nv, s.F[f2].ravel(), (g2 * coef).reshape(-1, 3))
    tail, head = s.E[e, 0], s.E[e, 1]
    gu = du * (0.5 * Le * w)[:, None] + (0.5 * theta * w)[:, None] * u   # + ½ θ dL
    g += scatter(s.nv, head, gu)
    g -= scatter(s.nv, tail, gu)
    return g


# -- Gaussian curvature ---------------------------------------------------------------------

def _angles(P):
    """Corner angles (nf, 3) of the facets and their gradients
    (nf, 3 corners, 3 points, 3): d(angle at a)/d x_b."""
    out = np.zeros(P.shape[:2])
    grad = np.zeros(P.shape[:2] + (3, 3))
    for a in range(3):
        b, c = (a + 1) % 3, (a + 2) % 3
        u = P[:, b] - P[:, a]
        v = P[:, c] - P[:, a]
        X = np.cross(u, v)
        S = np.linalg.norm(X, axis=1)
        C = np.einsum("ij,ij->i", u, v)
        R = S * S + C * C
        with np.errstate(all="ignore"):
            nh = np.nan_to_num(X / S[:, None])
            du = (C[:, None] * np.cross(v, nh) - S[:, None] * v) / R[:, None]
            dv = (C[:, None] * np.cross(nh, u) - S[:, None] * u) / R[:, None]
        out[:, a] = np.arctan2(S, C)
        grad[:, a, b] = du
        grad[:, a, c] = dv
        grad[:, a, a] = -(du + dv)
    return out, grad


def _gauss(t):
    """Angle defect K (nv,), star area A (nv,) and the per-facet pieces."""
    s = t.surface
    P = facet_points(t)
    ang, dang = _angles(P)
    K = 2 * np.pi - np.bincount(s.F.ravel(), weights=ang.ravel(), minlength=s.nv)
    A = np.bincount(s.F.ravel(), weights=np.repeat(t.facet_area, 3), minlength=s.nv)
    return K, A, P, dang


def star_gauss_values(ctx, m, idx):
    """``star_gauss_curvature``: the angle defect 2π − Σ angles at a vertex."""
    _check_supported(ctx.surface)
    K, _, _, _ = _gauss(ctx)
    return K[idx]


def sq_gauss_values(ctx, m, idx):
    """``sq_gauss_curvature``: K²/(A/3) at a vertex (closed surfaces)."""
    _check_closed(ctx.surface, "sq_gauss_curvature", True)
    K, A, _, _ = _gauss(ctx)
    return (K * K / (A / 3.0))[idx]


def _gauss_grad(t, idx, w, square):
    s = t.surface
    if square:
        _check_closed(s, "sq_gauss_curvature", True)
    else:
        _check_supported(s)
    K, A, P, dang = _gauss(t)
    wv = vertex_weights(s.nv, idx, w)
    if square:
        dK = 2 * K / (A / 3.0) * wv
        dA = -3.0 * K * K / (A * A) * wv
    else:
        dK, dA = wv, np.zeros(s.nv)
    Fc = s.F
    # K_v = 2π − Σ angles at v: d/dx of Σ_v dK_v K_v
    g = -np.einsum("fa,fabk->fbk", dK[Fc], dang)
    g += facet_area_grad(t) * dA[Fc].sum(axis=1)[:, None, None]
    return corner_scatter(t, g)


def star_gauss_gradient(t, m, idx, w):
    return _gauss_grad(t, np.asarray(idx, np.int64), np.asarray(w, float), False)


def sq_gauss_gradient(t, m, idx, w):
    return _gauss_grad(t, np.asarray(idx, np.int64), np.asarray(w, float), True)


# -- legacy SQUARED_CURVATURE ---------------------------------------------------------------

class _Legacy:
    def __init__(self, method):
        self.method = method


_LEGACY = {"plain": "sq_mean_curvature", "eff": "eff_area_sq_mean_curvature",
           "norm": "normal_sq_mean_curvature"}


def legacy_energy(t):
    """Σ_v E_v of the old vertex method the toggles select (spec §5.3):
    ``normal_curvature`` supersedes ``effective_area``."""
    s = t.surface
    m = _Legacy(_LEGACY[s.curvature_mode])
    return float(vertex_values(t, m, np.arange(s.nv)).sum())


def legacy_gradient(t):
    s = t.surface
    m = _Legacy(_LEGACY[s.curvature_mode])
    return vertex_gradient(t, m, np.arange(s.nv), np.ones(s.nv))


# -- cotan_sq_mean_curvature (Meyer, Desbrun, Schröder, Barr 2003) ------------------------

def _cot_and_grad(P):
    """Cotangents (nf, 3) of the corner angles and their gradients
    (nf, 3 corners, 3 points, 3), from :func:`_angles`:
    d cot θ = −dθ / sin² θ."""
    ang, dang = _angles(P)
    s = np.sin(ang)
    with np.errstate(all="ignore"):
        return np.cos(ang) / s, -dang / (s * s)[:, :, None, None]


def _mixed_areas(P, cot, cot_grad, Af, Ag):
    """MDSB mixed (Voronoi / obtuse-corrected) areas per facet corner
    (nf, 3) and their gradients (nf, 3 corners, 3 points, 3)."""
    nf = len(P)
    area = np.zeros((nf, 3))
    grad = np.zeros((nf, 3, 3, 3))
    obtuse = cot < 0                                          # angle > 90°
    any_obt = obtuse.any(axis=1)
    for i in range(3):
        j, k = (i + 1) % 3, (i + 2) % 3
        eij = P[:, j] - P[:, i]
        eik = P[:, k] - P[:, i]
        lij, lik = np.einsum("ij,ij->i", eij, eij), np.einsum("ij,ij->i", eik, eik)
        vor = (lij * cot[:, k] + lik * cot[:, j]) / 8.0
        dvor = (lij[:, None, None] * cot_grad[:, k] + lik[:, None, None] * cot_grad[:, j]) / 8.0
        dvor[:, j] += (2 * eij * cot[:, k, None]) / 8.0
        dvor[:, i] -= (2 * eij * cot[:, k, None]) / 8.0
        dvor[:, k] += (2 * eik * cot[:, j, None]) / 8.0
        dvor[:, i] -= (2 * eik * cot[:, j, None]) / 8.0
        frac = np.where(obtuse[:, i], 0.5, 0.25)
        area[:, i] = np.where(any_obt, frac * Af, vor)
        grad[:, i] = np.where(any_obt[:, None, None], frac[:, None, None] * Ag, dvor)
    return area, grad


def _cotan_parts(t):
    s = t.surface
    P = facet_points(t)
    cot, cg = _cot_and_grad(P)
    Af = t.facet_area
    Ag = facet_area_grad(t)
    Am, Amg = _mixed_areas(P, cot, cg, Af, Ag)
    Fc = s.F
    # S_v = Σ_f [cot_{c+2} (x_c − x_{c+1}) + cot_{c+1} (x_c − x_{c+2})]
    Sc = np.zeros((len(P), 3, 3))
    for c in range(3):
        c1, c2 = (c + 1) % 3, (c + 2) % 3
        Sc[:, c] = cot[:, c2, None] * (P[:, c] - P[:, c1]) + cot[:, c1, None] * (P[:, c] - P[:, c2])
    flat = Fc.ravel()
    Sv = _scatter(s.nv, flat, Sc.reshape(-1, 3))
    Av = np.bincount(flat, weights=Am.ravel(), minlength=s.nv)
    return P, cot, cg, Am, Amg, Sv, Av


def _cotan_normals(t, Fc):
    """Unit area-weighted vertex normals ``n̂_v = N_v/|N_v|``, ``N_v = Σ_f ½ N2_f``
    over the star, and ``|N_v|`` (the normal of the spontaneous-curvature term)."""
    s = t.surface
    N = _scatter(s.nv, Fc.ravel(), 0.5 * np.repeat(t.facet_N2, 3, axis=0))
    nN = np.linalg.norm(N, axis=1)
    with np.errstate(all="ignore"):
        return np.nan_to_num(N / nN[:, None]), nN


def cotan_values(ctx, m, idx):
    """``cotan_sq_mean_curvature``: Σ_v H_v² A_v with the cotangent mean
    curvature normal K = S/(2A) = 2H n and mixed areas A (MDSB 2003), i.e.
    ``|S_v|² / (16 A_v)``; pyevolver's own method (paper's W_MDSB).

    With ``h_zero`` (parameter or vertex attribute) the vertex energy is
    ``A_v |K_v/2 − h0 n̂_v|² = |S_v|²/(16 A_v) − (h0/2) S_v·n̂_v + h0² A_v``,
    ``n̂_v`` the unit area-weighted vertex normal: the Helfrich energy
    ``∫(H − h0)² dA`` written with the mean curvature vector ``K/2 = H n``
    of Meyer et al. 2003 (pyevolver's own form, no reference program has
    it), equal to
    ``(H_v − h0)² A_v`` where ``K_v ∥ n̂_v`` and to the h_zero-less energy
    at ``h0 = 0``.  Sign: ``S_v·n̂_v > 0`` on a sphere with outward facets
    (H > 0, the Evolver's convention for h_zero)."""
    s = ctx.surface
    _check_closed(s, "cotan_sq_mean_curvature")
    _, _, _, _, _, Sv, Av = _cotan_parts(ctx)
    with np.errstate(all="ignore"):
        E = np.nan_to_num(np.einsum("ij,ij->i", Sv, Sv) / (16.0 * Av))
    h0 = _h_zero(s, "cotan_sq_mean_curvature")
    if h0 is not None:
        nh, _ = _cotan_normals(ctx, s.F)
        E = E - 0.5 * h0 * np.einsum("ij,ij->i", Sv, nh) + h0 * h0 * Av
    return E[idx]


def cotan_gradient(t, m, idx, w):
    s = t.surface
    _check_closed(s, "cotan_sq_mean_curvature")
    P, cot, cg, Am, Amg, Sv, Av = _cotan_parts(t)
    wv = vertex_weights(s.nv, idx, w)
    with np.errstate(all="ignore"):
        uS = np.nan_to_num(Sv / (8.0 * Av)[:, None]) * wv[:, None]
        uA = np.nan_to_num(-np.einsum("ij,ij->i", Sv, Sv) / (16.0 * Av * Av)) * wv
    Fc = s.F
    h0 = _h_zero(s, "cotan_sq_mean_curvature")
    gN = None
    if h0 is not None:
        # − (h0/2) S·n̂ + h0² A: through S, A and n̂ = N/|N| (N = Σ ½ N2_f)
        nh, nN = _cotan_normals(t, Fc)
        uS = uS - (0.5 * h0 * wv)[:, None] * nh
        uA = uA + h0 * h0 * wv
        with np.errstate(all="ignore"):
            S_perp = Sv - nh * np.einsum("ij,ij->i", nh, Sv)[:, None]    # (I − n̂n̂ᵀ) S
            dN = np.nan_to_num(S_perp / nN[:, None]) * (-0.5 * h0 * wv)[:, None]
        gN = 0.5 * n2_grad_dot(P, dN[Fc].sum(axis=1))
    U = uS[Fc]                                             # (nf, 3, 3)
    g = np.zeros_like(P)
    for k in range(3):
        a, b = (k + 1) % 3, (k + 2) % 3
        dU = U[:, a] - U[:, b]
        D = np.einsum("ij,ij->i", dU, P[:, a] - P[:, b])
        g += D[:, None, None] * cg[:, k]
        g[:, a] += cot[:, k, None] * dU
        g[:, b] -= cot[:, k, None] * dU
    g += np.einsum("fc,fcpk->fpk", uA[Fc], Amg)
    if gN is not None:
        g += gN
    return corner_scatter(t, g)


# -- circle_willmore (Bobenko's conformal energy) ---------------------------------------------

def _edge_quads(s):
    """For every edge with two facets: its ends ``i, j`` and the third
    vertices ``k, l`` of its two facets (edges (nq,), vertices 4 × (nq,))."""
    ef, ek, val = edge_facets(s)
    e = np.nonzero(val == 2)[0]
    F = s.F
    f1, f2 = ef[e, 0], ef[e, 1]
    k1, k2 = ek[e, 0], ek[e, 1]
    # the side k of a facet runs from corner k to corner k+1: its opposite corner is k+2
    k = F[f1, (k1 + 2) % 3]
    l_ = F[f2, (k2 + 2) % 3]
    return e, s.E[e, 0], s.E[e, 1], k, l_


def _bobenko_beta(X, i, j, k, l_, grad=False):
    """β of each edge: the angle between the circumcircles of its two
    facets, computed after inversion about x_i (β is Möbius invariant), where
    the circles become the lines j'k' and j'l': β = π − ∠(k' − j', l' − j')."""
    def inv(p):
        r2 = np.einsum("ij,ij->i", p, p)
        return p / r2[:, None], r2

    a, ra = inv(X[j] - X[i])
    b, rb = inv(X[k] - X[i])
    c, rc = inv(X[l_] - X[i])
    u, v = b - a, c - a
    w = np.cross(u, v)
    S = np.linalg.norm(w, axis=1)
    C = np.einsum("ij,ij->i", u, v)
    beta = np.pi - np.arctan2(S, C)
    if not grad:
        return beta
    R = S * S + C * C
    with np.errstate(all="ignore"):
        nh = np.nan_to_num(w / S[:, None])
        dth_du = (C[:, None] * np.cross(v, nh) - S[:, None] * v) / R[:, None]
        dth_dv = (C[:, None] * np.cross(nh, u) - S[:, None] * u) / R[:, None]
    dbu, dbv = -dth_du, -dth_dv                   # β = π − θ

    def inv_t(p_inv, r2, g):
        # d(p/|p|²) = (I − 2 p̂ p̂ᵀ)/|p|² dp, symmetric: transpose = itself
        ph = p_inv * np.sqrt(r2)[:, None]         # unit vector of p
        return (g - 2 * ph * np.einsum("ij,ij->i", ph, g)[:, None]) / r2[:, None]
    gj = inv_t(a, ra, -(dbu + dbv))
    gk = inv_t(b, rb, dbu)
    gl = inv_t(c, rc, dbv)
    gi = -(gj + gk + gl)
    return beta, (gi, gj, gk, gl)


def circle_willmore_values(ctx, m, idx):
    """``circle_willmore``: Bobenko's W = Σ_e β_e − π V, as per-vertex values
    ½ Σ_{e∋v} β_e − π (REF: 0 on polyhedra inscribed in a sphere, 1.1430603354544
    on blob0.fe).  Not differentiable where some β = 0 or π."""
    s = ctx.surface
    _check_closed(s, "circle_willmore")
    _check_supported(s, "circle_willmore")
    e, i, j, k, l_ = _edge_quads(s)
    beta = _bobenko_beta(s.X, i, j, k, l_)
    per_v = 0.5 * (np.bincount(i, weights=beta, minlength=s.nv)
                   + np.bincount(j, weights=beta, minlength=s.nv)) - np.pi
    return per_v[idx]


def circle_willmore_gradient(t, m, idx, w):
    s = t.surface
    _check_closed(s, "circle_willmore")
    _check_supported(s, "circle_willmore")
    wv = vertex_weights(s.nv, idx, w)
    e, i, j, k, l_ = _edge_quads(s)
    _, (gi, gj, gk, gl) = _bobenko_beta(s.X, i, j, k, l_, grad=True)
    coef = 0.5 * (wv[i] + wv[j])[:, None]
    g = np.zeros((s.nv, 3))
    for v, gv in ((i, gi), (j, gj), (k, gk), (l_, gl)):
        g += _scatter(s.nv, v, gv * coef)
    return g
