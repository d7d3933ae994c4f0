"""The string model: a one-dimensional surface (spec §3.2, §4, Tier 2).

The Evolver's ``STRING`` (or ``SURFACE_DIMENSION 1``) datafiles describe
curves: edges carry the energy (tension 1 unless given), and a *facet* is a
chain of edges, not necessarily closed, that exists to give a body its
"volume", the area of the facet (manual, "The string model").  Such files
are two-dimensional (``SPACE_DIMENSION 2``: slidestr.fe) when they have
bodies, or curves in space without facets (popstr.fe, knotty.fe).

pyevolver keeps the coordinates of a two-dimensional surface in the same
``(nv, 3)`` array as any other, with a z column that stays zero: no
energy or constraint of a two-dimensional file can depend on z, so no force
has a z component.

Facet area and gravity use one-dimensional divergence theorems over the
facet's edges, as REF does (the values below agree with ``evolver-nox-d``
to round-off on slidestr.fe and test files):

* area of the region left of a chain: ``A = Σ_e -∫ y dx``, per edge
  ``-(x_h - x_t)(y_t + y_h)/2`` (t, h: the edge's tail and head as the
  facet traverses it);
* gravity of a body of density ρ: ``G ρ ∬ y dA = Σ_e -G ρ ∫ y²/2 dx``, per
  edge ``-(x_h - x_t)(y_t² + y_t y_h + y_h²)/6``;
* constraint CONTENT and ENERGY integrands are single functions of the
  point, evaluated at the vertices on the constraint (manual, "Constraints");
  energy adds ``E(v)`` for every such vertex, content adds ``C(head) -
  C(tail)`` for each edge of a facet whose head or tail is on the
  constraint (so only the ends of an open chain count: the content is the
  integral along the constraint that closes the chain).  FIXED vertices
  count too (REF).

The facets are stored as one ragged array: ``s.sf_enc`` holds every
facet's edges in chain order (edge index ``e`` forwards, ``~e`` backwards)
and facet ``f`` is ``sf_enc[sf_ptr[f]:sf_ptr[f + 1]]``.
"""
from __future__ import annotations

import numpy as np

from ..errors import CommandError, UnsupportedError
from .surface import Totals

# quantity methods that make sense without facets
STRING_METHODS = {"edge_length", "edge_tension", "edge_area", "vertex_scalar_integral",
                  "edge_scalar_integral", "edge_vector_integral", "harmonic_energy"}


# ---------------------------------------------------------------------------
# facets as chains


def chain_points(s, t=None):
    """``(Pt, Ph)`` (m, 3): the tail and head points of every (facet, edge)
    incidence as the facet traverses them.  On a torus the chain is unwrapped
    from the tail of its first edge (edge vectors with their period shifts
    added up along the chain), so areas and gravity see one connected curve."""
    owner, e, sgn, tail, head = facet_entries(s)
    if s.periods is None:
        return s.X[tail], s.X[head]
    from ..geometry.kernels import edge_vectors
    ev = t.edge_vec if t is not None else edge_vectors(s.X, s.E, s.wrap_shift())
    d = ev[e] * sgn[:, None]
    if not len(d):
        return s.X[tail], s.X[head]
    cs = np.cumsum(d, axis=0) - d               # sum of the edges before each one
    start = s.sf_ptr[:-1]
    Pt = s.X[tail[start]][owner] + cs - cs[start][owner]
    return Pt, Pt + d


def facet_entries(s):
    """``(owner, edge, sign, tail, head)`` for every (facet, edge) incidence,
    arrays of shape (m,): the facet, the edge index, +1/-1 for the direction
    of traversal, and the vertices the facet goes from and to."""
    enc = s.sf_enc
    owner = np.repeat(np.arange(len(s.sf_ptr) - 1), np.diff(s.sf_ptr))
    fwd = enc >= 0
    e = np.where(fwd, enc, ~enc)
    tail = np.where(fwd, s.E[e, 0], s.E[e, 1])
    head = np.where(fwd, s.E[e, 1], s.E[e, 0])
    return owner, e, np.where(fwd, 1.0, -1.0), tail, head


def chain(s, f):
    """Encoded edges of facet ``f`` in chain order."""
    return s.sf_enc[s.sf_ptr[f]:s.sf_ptr[f + 1]]


def chain_vertices(s, f, sign=1):
    """Vertices of facet ``f`` along its chain: n + 1 for an open chain of n
    edges, n for a closed one (manual, facet ``vertices``); ``sign`` -1
    walks it backwards."""
    enc = chain(s, f)
    if sign < 0:
        enc = ~enc[::-1]
    fwd = enc >= 0
    e = np.where(fwd, enc, ~enc)
    tails = np.where(fwd, s.E[e, 0], s.E[e, 1])
    last = s.E[e[-1], 1] if fwd[-1] else s.E[e[-1], 0]
    vs = list(tails)
    if last != tails[0]:
        vs.append(last)
    return [int(v) for v in vs]


def facets_of_edge(s, e):
    """``[(facet, sign)]`` of the facets whose chain contains edge ``e``."""
    owner, ee, sgn, _, _ = facet_entries(s)
    hit = np.nonzero(ee == e)[0]
    return [(int(owner[k]), int(sgn[k])) for k in hit]


def facetedge_count(s):
    """REF's facet-edge count: one per (facet, edge) incidence, and one for
    each edge on no facet."""
    on = np.bincount(facet_entries(s)[1], minlength=s.ne)
    return int(np.maximum(on, 1).sum())


# ---------------------------------------------------------------------------
# energies and areas


def _edge_area(Pt, Ph):
    return -(Ph[:, 0] - Pt[:, 0]) * (Pt[:, 1] + Ph[:, 1]) / 2.0


def _edge_gravity(Pt, Ph):
    yt, yh = Pt[:, 1], Ph[:, 1]
    return -(Ph[:, 0] - Pt[:, 0]) * (yt * yt + yt * yh + yh * yh) / 6.0


def _vertex_integrand(s, which):
    """``[(formula, vertex mask)]`` of constraint ENERGY / CONTENT integrands
    (their single component) with the vertices on the constraint."""
    from .surface import LocatedFormula
    out = []
    for cid, on in s.vcon.items():
        c = s.constraints[cid]
        comps = getattr(c, which)
        if comps and on.any():
            out.append((LocatedFormula(comps[0], f"constraint {cid} {which}",
                                       getattr(c, "line", None)), on))
    return out


def _point_values(s, formula, idx):
    P = s.X[idx]
    coords = {"x": P[:, 0], "y": P[:, 1], "z": P[:, 2]}
    return formula.values(s.param_env(), coords, len(idx))


def _point_gradients(s, formula, idx):
    P = s.X[idx]
    coords = {"x": P[:, 0], "y": P[:, 1], "z": P[:, 2]}
    return formula.gradient(s.param_env(), coords, len(idx))


def content_coefficients(s, on):
    """(nf, nv) counts head - tail of the vertices in ``on`` over each
    facet's edges, as a dense-free list ``(facet, vertex, coef)``."""
    owner, _, _, tail, head = facet_entries(s)
    f = np.concatenate([owner, owner])
    v = np.concatenate([head, tail])
    c = np.concatenate([np.ones(len(head)), -np.ones(len(tail))])
    keep = on[v]
    return f[keep], v[keep], c[keep]


def vertex_energy(s):
    """Sum of the constraint ENERGY integrands at the vertices on them."""
    total = 0.0
    for formula, on in _vertex_integrand(s, "energy"):
        total += float(np.sum(_point_values(s, formula, np.nonzero(on)[0])))
    return total


def facet_areas(s, t=None):
    """(nf,) areas of the string facets, content integrals included."""
    nsf = len(s.sf_ptr) - 1
    owner = facet_entries(s)[0]
    area = np.bincount(owner, weights=_edge_area(*chain_points(s, t)), minlength=nsf)
    for formula, on in _vertex_integrand(s, "content"):
        f, v, c = content_coefficients(s, on)
        if len(f):
            area += np.bincount(f, weights=c * _point_values(s, formula, v), minlength=nsf)
    return area


def facet_gravity(s, t=None):
    """(nf,) ∬ y dA of each facet (per unit G ρ)."""
    owner = facet_entries(s)[0]
    return np.bincount(owner, weights=_edge_gravity(*chain_points(s, t)),
                       minlength=len(s.sf_ptr) - 1)


# ---------------------------------------------------------------------------
# gradients


def _chain_grad(s, per_facet, fn):
    """Gradient of Σ_f w_f Σ_{edges of f} fn-term (fn gives the tail and head
    derivatives, each (m, 3))."""
    owner, _, _, tail, head = facet_entries(s)
    w = per_facet[owner]
    gt, gh = fn(*chain_points(s))
    out = np.zeros((s.nv, 3))
    for k in range(2):
        out[:, k] = (np.bincount(tail, weights=w * gt[:, k], minlength=s.nv)
                     + np.bincount(head, weights=w * gh[:, k], minlength=s.nv))
    return out


def _area_derivs(Pt, Ph):
    dx = Ph[:, 0] - Pt[:, 0]
    sy = Pt[:, 1] + Ph[:, 1]
    gt = np.stack([sy / 2.0, -dx / 2.0], axis=1)
    gh = np.stack([-sy / 2.0, -dx / 2.0], axis=1)
    return gt, gh


def _gravity_derivs(Pt, Ph):
    dx = Ph[:, 0] - Pt[:, 0]
    yt, yh = Pt[:, 1], Ph[:, 1]
    q = (yt * yt + yt * yh + yh * yh) / 6.0
    gt = np.stack([q, -dx * (2 * yt + yh) / 6.0], axis=1)
    gh = np.stack([-q, -dx * (yt + 2 * yh) / 6.0], axis=1)
    return gt, gh


def facet_area_gradient(s, per_facet):
    """Gradient (nv, 3) of Σ_f w_f A_f, content integrals included."""
    g = _chain_grad(s, per_facet, _area_derivs)
    for formula, on in _vertex_integrand(s, "content"):
        f, v, c = content_coefficients(s, on)
        if len(f):
            d = _point_gradients(s, formula, v) * (c * per_facet[f])[:, None]
            for k in range(3):
                g[:, k] += np.bincount(v, weights=d[:, k], minlength=s.nv)
    return g


def energy_gradient(t):
    """Gradient (nv, 3) of the total energy of a string surface."""
    from ..evolve.gradient import edge_length_grad, quantity_gradient
    s = t.surface
    et = s.edge_tension
    nz = np.nonzero(et)[0]
    g = edge_length_grad(t, nz, et[nz])
    for formula, on in _vertex_integrand(s, "energy"):
        idx = np.nonzero(on)[0]
        d = _point_gradients(s, formula, idx)
        g[idx] += d
    b = s.bodies
    if b.n:
        if s.gravity_constant != 0 and s.gravity_on and np.any(b.density):
            w = s.gravity_constant * (b.facet_matrix.T @ b.density)
            g += _chain_grad(s, np.asarray(w, float), _gravity_derivs)
        pmask = ~np.isnan(b.pressure)
        for i in np.nonzero(pmask)[0]:
            g -= b.pressure[i] * body_gradient(s, i)
    for q in s.quantities.values():
        if q.kind == "energy":
            g += quantity_gradient(t, q)
    return g


def body_gradient(s, i):
    w = np.asarray(s.bodies.facet_matrix.getrow(i).todense()).ravel()
    return facet_area_gradient(s, w)


def volume_gradients(t):
    """(nb, nv, 3) gradients of the body areas."""
    s = t.surface
    return np.stack([body_gradient(s, i) for i in range(s.bodies.n)]) if s.bodies.n else \
        np.zeros((0, s.nv, 3))


# ---------------------------------------------------------------------------
# the edges around a vertex


def init_rings(s):
    """REF keeps the edges at a vertex in a ring with a first edge; a new
    edge goes in right after the first, and when the first goes the next one
    takes its place, so ``vv.edge`` lists the first edge, then the others
    newest first.  ``eattr["ring_time"]`` (ne, 2) holds when each end of an
    edge joined its vertex's ring, ``vattr["ring_head"]`` each vertex's
    first edge.  On load edges join in datafile order."""
    ne, nv = s.ne, s.nv
    s.eattr["ring_time"] = np.repeat(np.arange(ne, dtype=np.int64)[:, None], 2, axis=1)
    head = np.full(nv, ne, np.int64)
    np.minimum.at(head, s.E[:, 0], np.arange(ne))
    np.minimum.at(head, s.E[:, 1], np.arange(ne))
    s.vattr["ring_head"] = np.where(head == ne, -1, head)


def vertex_edges(s, v):
    """Edges at vertex ``v`` in REF's order: ``[(edge, +1 if v is its tail
    else -1)]``."""
    ends = np.nonzero(s.E == v)
    e, end = ends[0], ends[1]
    t = s.eattr["ring_time"][e, end]
    head = s.vattr["ring_head"][v]
    key = np.where(e == head, np.iinfo(np.int64).max, t)
    order = np.argsort(-key, kind="stable")
    return [(int(e[k]), 1 if end[k] == 0 else -1) for k in order]


def _ring_split(s, t, R, mid, half):
    """Update the rings for edges ``R`` split at new vertices ``mid`` with
    new head halves ``half`` (REF's order after ``r``, measured on
    popstr.fe): edges are processed in order; the new vertex gets the new
    half first, then the old edge; at the old head vertex the old edge
    leaves its ring and the new half joins it."""
    times = t.eattr["ring_time"]
    head = t.vattr["ring_head"]
    clock = int(times.max()) + 1 if len(times) else 0
    # the edges as they are while the splits are done one after the other
    E = np.vstack([s.E, np.full((len(R), 2), -1, np.int64)])
    for e, m, n in zip(R.tolist(), mid.tolist(), half.tolist()):
        h = int(E[e, 1])
        E[e, 1] = m
        head[m] = n
        times[n, 0] = clock
        times[e, 1] = clock + 1
        if head[h] == e:
            # the next in the ring: the newest of the others
            at = np.nonzero((E == h).any(axis=1))[0]
            if len(at):
                tt = np.where(E[at, 0] == h, times[at, 0], times[at, 1])
                head[h] = at[np.argmax(tt)]
            else:
                head[h] = n
        E[n] = (m, h)
        times[n, 1] = clock + 2
        clock += 3


# ---------------------------------------------------------------------------
# mesh operations


def split_edges(s, R):
    """Bisect the edges ``R`` (indices): midpoint vertices numbered in edge
    order, the original edge keeps its tail half and the head halves are new
    edges in the same order; each facet chain gets the new half next to its
    parent (REF's numbering, ``list facets`` after ``r``)."""
    from ..remesh.grow import grow
    from .surface import constrained_vertices, project_to_constraints
    R = np.asarray(R, np.int64)
    k = len(R)
    t = grow(s, v_from_edge=R, e_from_edge=R)
    nv, ne = s.nv, s.ne
    mid = nv + np.arange(k)
    half = ne + np.arange(k)
    if s.periods is None:
        t.X[mid] = 0.5 * (s.X[s.E[R, 0]] + s.X[s.E[R, 1]])
    else:                                 # the head as seen from the tail
        from ..geometry.kernels import edge_vectors
        t.X[mid] = s.X[s.E[R, 0]] + 0.5 * edge_vectors(s.X, s.E, s.wrap_shift())[R]
    if "wrap" in t.eattr:
        t.eattr["wrap"][R] = 0.0          # the tail half stays in the tail's cell
    t.E[half, 0] = mid
    t.E[half, 1] = s.E[R, 1]
    t.E[R, 1] = mid
    if "ring_time" in s.eattr:
        t.eattr["ring_time"] = t.eattr["ring_time"].copy()
        t.vattr["ring_head"] = t.vattr["ring_head"].copy()
        _ring_split(s, t, R, mid, half)
    # facet chains: e -> e, h ; ~e -> ~h, ~e
    newh = np.full(ne, -1, np.int64)
    newh[R] = half
    enc = s.sf_enc
    fwd = enc >= 0
    e = np.where(fwd, enc, ~enc)
    split = newh[e] >= 0
    reps = np.where(split, 2, 1)
    out = np.empty(int(reps.sum()), np.int64)
    pos = np.cumsum(reps) - reps
    out[pos] = np.where(split & ~fwd, ~newh[e], enc)
    sp = np.nonzero(split)[0]
    out[pos[sp] + 1] = np.where(fwd[sp], newh[e[sp]], enc[sp])
    owner = np.repeat(np.arange(len(s.sf_ptr) - 1), np.diff(s.sf_ptr))
    t.sf_enc = out
    t.sf_ptr = np.concatenate([[0], np.cumsum(np.bincount(owner, weights=reps,
                                                           minlength=len(s.sf_ptr) - 1))]
                              ).astype(np.int64)
    sel = mid[constrained_vertices(t)[mid]]
    if len(sel):
        project_to_constraints(t, sel)
    return t


def vertex_average(s, mode="V"):
    """``V`` / ``rawv`` / ``rawestv`` on a string (measured on REF): a vertex
    with two or more usable edges moves by a quarter of the mean of its
    neighbours minus itself, ``D = Σ_e (x_e - x_v) / n``, ``x += D/4``;
    ``V`` moves only vertices with exactly two edges and keeps only the
    component of D along the chord between the two neighbours (the tangent:
    the area is kept to first order).  Vertices that are FIXED, on a
    boundary or at the end of a string do not move; for ``V`` and ``rawv`` a
    vertex on constraints uses only edges on the same constraints (as in
    the soapfilm model) and is projected back."""
    import copy
    from .surface import project_to_constraints, project_tangent
    nv, ne = s.nv, s.ne
    v = np.concatenate([s.E[:, 0], s.E[:, 1]])
    other = np.concatenate([s.E[:, 1], s.E[:, 0]])
    use = np.ones(2 * ne, bool)
    if mode != "rawest" and s.vcon:
        e = np.concatenate([np.arange(ne), np.arange(ne)])
        for c, on_v in s.vcon.items():
            on_e = s.econ.get(c)
            on_e = np.zeros(ne, bool) if on_e is None else (on_e != 0)
            use &= ~on_v[v] | on_e[e]
    deg = np.bincount(v, minlength=nv)
    cnt = np.bincount(v, weights=use.astype(float), minlength=nv)
    from ..geometry.kernels import edge_vectors
    ev = edge_vectors(s.X, s.E, s.wrap_shift())
    vec = np.concatenate([ev, -ev])
    D = np.zeros((nv, 3))
    for k in range(3):
        D[:, k] = np.bincount(v, weights=np.where(use, vec[:, k], 0.0), minlength=nv)
    movable = ~s.vattr["fixed"] & (cnt >= 2)
    if mode == "V":
        movable &= (cnt == 2) & (deg == 2)
    bnd = s.vattr.get("boundary")
    if bnd is not None:
        movable &= bnd == 0
    D[~movable] = 0.0
    D[movable] /= cnt[movable, None]
    if mode == "V":
        mv = np.nonzero(movable)[0]
        # the chord between the two neighbours, as seen from the vertex
        # (torus wraps included)
        order = np.argsort(v, kind="stable")
        first = np.searchsorted(v[order], mv)
        ch = vec[order[first + 1]] - vec[order[first]]
        n2 = np.einsum("ij,ij->i", ch, ch)
        with np.errstate(all="ignore"):
            tang = np.where(n2[:, None] > 0, ch * (np.einsum("ij,ij->i", D[mv], ch) / n2)[:, None],
                            0.0)
        D[mv] = tang
        (D,) = project_tangent(s, [D])
    new = copy.copy(s)
    new.X = s.X + D / 4.0
    if new.vcon:
        project_to_constraints(new, np.nonzero(movable)[0])
    return new


def refuse(what):
    """Commands that are not available in the string model."""
    raise UnsupportedError(f"{what} in the string model")


def check_no_facets_needed(s, what):
    if s.string:
        raise CommandError(f"{what} needs facets: not available in the string model")


# ---------------------------------------------------------------------------
# totals


class StringTotals(Totals):
    """Energy, length and body areas of a string surface (the attributes
    of :class:`pyevolver.model.surface.Totals`; ``total_area`` is the total
    length, as in REF)."""

    def __init__(self, s):
        self.surface = s
        self.facet_area = np.zeros(0)
        self.facet_volume = np.zeros(0)
        self.facet_N2 = np.zeros((0, 3))
        self.total_area = self.total_length
        self.terms = {}
        energy = float(self.edge_length @ s.edge_tension)
        self.terms["edge_tension"] = energy
        self.con_energy = vertex_energy(s)
        self.con_content = None
        energy += self.con_energy
        b = s.bodies
        self.sfacet_area = facet_areas(s, self) if len(s.sf_ptr) > 1 else np.zeros(0)
        self.volumes = (b.facet_matrix @ self.sfacet_area + b.volconst) if b.n else \
            np.zeros(0)
        self.energy = self._finish_energy(energy, self._gravity() if b.n else 0.0)

    def _facet_gravity(self):
        return facet_gravity(s=self.surface, t=self)

    def volume_magnitudes(self):
        s = self.surface
        owner = facet_entries(s)[0]
        per = np.bincount(owner, weights=np.abs(_edge_area(*chain_points(s, self))),
                          minlength=len(s.sf_ptr) - 1)
        return abs(s.bodies.facet_matrix) @ per
