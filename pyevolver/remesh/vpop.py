"""``o`` / ``pop vertex``: find (and pop) the non-minimal vertices of a soap
film (manual: o, pop).

A vertex of a soap film is minimal when the surface near it is one of the
three cones of Plateau's rules: a disc, three sheets on a triple line, or
six sheets meeting four triple lines at a tetrahedral point.  pyevolver
reads this off the vertex's *link*: a graph whose nodes are the edges at the
vertex (a node's degree is the edge's number of facets) and whose arcs are
the facets at the vertex (a facet joins its two edges at the vertex).  The
link of a minimal vertex is connected, its nodes have degree 2 or 3, and it
has no triple node (a disc), two (a triple line) or four (a tetrahedral
point).  A disconnected link is a pair of cones touching at the vertex; more
than four triple nodes (the manual: "more than four triple edges
adjacent"), or a node of degree four or more, is non-minimal too.

As the manual says, only interior vertices are tested: vertices that are
FIXED, on a constraint or a boundary, or on an edge with fewer than two
facets (the film's free border) are left alone; so are vertices of bare
edges.  These rules were checked against evolver-nox-d on every shipped
soap-film example (none of which has a non-minimal vertex after ``g 5``
but octa.fe, whose centre after the edge pops ``o`` does first has twelve
triple edges).

The pop itself (the manual's sphere round the vertex, cut by the facets,
its largest cell removed) is in :func:`pop_vertices`.
"""
from __future__ import annotations

import numpy as np
import scipy.sparse as sps

from ..errors import UnsupportedError
from .grow import grow
from .shrink import subset


def _edge_valence(s):
    a = np.where(s.FE >= 0, s.FE, ~s.FE).ravel()
    return np.bincount(a, minlength=s.ne)


def link_summary(s):
    """Per vertex: (tested, components, triple nodes, high nodes).

    ``tested`` is False for the vertices the Evolver leaves alone (fixed, on
    a constraint or boundary, on an edge with fewer than two facets, or with
    no facet at all); ``components`` counts the connected pieces of the
    link, ``triple`` its nodes of degree 3, ``high`` those of degree 4 or
    more.
    """
    nv, ne = s.nv, s.ne
    val = _edge_valence(s)
    E = s.E
    # link nodes: edge ends, 2e (tail) and 2e+1 (head)
    idx = np.where(s.FE >= 0, s.FE, ~s.FE)              # (nf, 3)
    F = s.F                                             # corner k is the tail of FE[:, k]
    # at corner k the facet's two edges are FE[:, k] (leaving) and FE[:, k-1] (arriving)
    rows, cols = [], []
    for k in range(3):
        v = F[:, k]
        e1, e2 = idx[:, k], idx[:, k - 1]
        n1 = 2 * e1 + (E[e1, 0] != v)
        n2 = 2 * e2 + (E[e2, 0] != v)
        rows.append(n1)
        cols.append(n2)
    rows = np.concatenate(rows) if rows else np.zeros(0, np.int64)
    cols = np.concatenate(cols) if cols else np.zeros(0, np.int64)
    nn = 2 * ne
    g = sps.coo_matrix((np.ones(len(rows)), (rows, cols)), shape=(nn, nn))
    from scipy.sparse.csgraph import connected_components   # (start-up time)
    _, comp = connected_components(g, directed=False)
    owner = E.ravel()                                   # vertex of each end
    nodeval = np.repeat(val, 2)
    # components per vertex: unique (vertex, component) pairs
    pair = np.unique(owner.astype(np.int64) * (nn + 1) + comp)
    ncomp = np.bincount(pair // (nn + 1), minlength=nv)
    triple = np.bincount(owner, weights=(nodeval == 3), minlength=nv).astype(np.int64)
    high = np.bincount(owner, weights=(nodeval >= 4), minlength=nv).astype(np.int64)
    low = np.bincount(owner, weights=(nodeval <= 1), minlength=nv) > 0
    deg = np.bincount(owner, minlength=nv)
    tested = ~low & (deg > 0) & ~s.vattr["fixed"]
    for on in s.vcon.values():
        tested &= ~np.asarray(on, bool)
    if "boundary" in s.vattr:
        tested &= s.vattr["boundary"] == 0
    return tested, ncomp, triple, high


def nonminimal_vertices(s, which=None):
    """Indices (ascending) of the tested vertices whose link is not one of
    the three minimal cones; ``which`` restricts the test to those vertex
    indices (``pop vertex[...]``)."""
    if s.string or s.nf == 0:
        return np.zeros(0, np.int64)
    tested, ncomp, triple, high = link_summary(s)
    bad = tested & ((ncomp > 1) | (high > 0) | (triple > 4) | (triple % 2 == 1))
    if which is not None:
        keep = np.zeros(s.nv, bool)
        keep[np.asarray(which, np.int64)] = True
        bad &= keep
    return np.nonzero(bad)[0]


def _star(s, v):
    """Spokes (edge indices, their far ends) and facets at vertex ``v``."""
    sp = np.nonzero((s.E[:, 0] == v) | (s.E[:, 1] == v))[0]
    far = np.where(s.E[sp, 0] == v, s.E[sp, 1], s.E[sp, 0])
    fs = np.nonzero((s.F == v).any(axis=1))[0]
    return sp, far, fs


def _cells(s, v, sp, fs, X=None):
    """The complement regions of the surface near ``v``: each a list of
    (facet, side) with side +1 for the facet's normal side.

    Round each spoke the facets are sorted by their angle about the spoke
    (outward from ``v``); the region between two neighbours touches the
    first on the side the rotation leaves it and the second on the side it
    arrives at.  ``X``: the positions to use (the torus: the far ends
    lifted next to ``v``).
    """
    X = s.X if X is None else X
    F = s.F
    N = np.cross(X[F[fs, 1]] - X[F[fs, 0]], X[F[fs, 2]] - X[F[fs, 0]])
    pos = {int(f): k for k, f in enumerate(fs)}
    parent = list(range(2 * len(fs)))

    def find(a):
        while parent[a] != a:
            parent[a] = parent[parent[a]]
            a = parent[a]
        return a

    absFE = np.where(s.FE >= 0, s.FE, ~s.FE)
    for e in sp:
        a, b = s.E[e]
        p = b if a == v else a
        d = X[p] - X[v]
        d = d / np.linalg.norm(d)
        on = [k for k, f in enumerate(fs) if e in absFE[f]]
        c = np.array([next(w for w in F[fs[k]] if w != v and w != p) for k in on])
        u = X[c] - X[v]
        u = u - np.outer(u @ d, d)
        ref = u[0] / np.linalg.norm(u[0])
        side = np.cross(d, ref)
        ang = np.mod(np.arctan2(u @ side, u @ ref), 2 * np.pi)
        order = np.argsort(ang, kind="stable")
        for i in range(len(order)):
            k1, k2 = on[order[i]], on[order[(i + 1) % len(order)]]
            u1, u2 = u[order[i]], u[order[(i + 1) % len(order)]]
            s1 = 1 if N[k1] @ np.cross(d, u1) > 0 else -1          # leaving k1
            s2 = 1 if N[k2] @ np.cross(d, u2) < 0 else -1          # arriving at k2
            x, y = 2 * k1 + (s1 < 0), 2 * k2 + (s2 < 0)
            parent[find(x)] = find(y)
    groups = {}
    for i in range(2 * len(fs)):
        groups.setdefault(find(i), []).append((int(fs[i // 2]), 1 if i % 2 == 0 else -1))
    return list(groups.values())


#: the Evolver merges two cones meeting at a vertex into a neck when their
#: facets are this flat: (|N1| + |N2|) / (A1 + A2) above it, with Ni the vector
#: area and Ai the area of cone i's facets at the vertex (measured with
#: evolver-nox-d on coaxial, tilted and unequal double cones of 4, 6 and 8
#: facets: the threshold is 0.8800 to four digits in every family)
CONE_MERGE = 0.88


def _cone_count(s, v):
    _, ncomp, _, _ = link_summary(s)
    return int(ncomp[v])


def _cones(s, v):
    """The link components of ``v``: per component its spokes (edge
    indices) and facets; refuses components that are not simple cycles."""
    vid = int(s.ids("vertex")[v])
    sp, far, fs = _star(s, v)
    absFE = np.where(s.FE >= 0, s.FE, ~s.FE)
    parent = {int(e): int(e) for e in sp}

    def find(a):
        while parent[a] != a:
            a = parent[a]
        return a
    fsp = []
    for f in fs:
        es = [int(e) for e in absFE[f] if int(e) in parent]
        if len(es) != 2:
            raise UnsupportedError("popping a vertex with a degenerate facet", f"vertex {vid}")
        fsp.append(es)
        parent[find(es[0])] = find(es[1])
    roots = sorted({find(int(e)) for e in sp})
    val = _edge_valence(s)
    out = []
    for r in roots:
        ce = [int(e) for e in sp if find(int(e)) == r]
        cf = [int(f) for f, es in zip(fs, fsp) if find(es[0]) == r]
        if (val[ce] != 2).any() or len(cf) != len(ce):
            raise UnsupportedError("popping a vertex where cones meet with triple edges",
                                   f"vertex {vid}")
        out.append((ce, cf))
    if len(out) != 2:
        raise UnsupportedError(f"popping a vertex where {len(out)} cones meet", f"vertex {vid}")
    return out


def cone_flatness(s, v, cones):
    """(|N1| + |N2|) / (A1 + A2) of the two cones at ``v`` (see CONE_MERGE)."""
    num = den = 0.0
    for ce, cf in cones:
        # orient the cone's facets coherently by walking round its link cycle
        far = {e: int(s.E[e, 1] if s.E[e, 0] == v else s.E[e, 0]) for e in ce}
        absFE = np.where(s.FE >= 0, s.FE, ~s.FE)
        arcs = {f: [int(e) for e in absFE[f] if int(e) in far] for f in cf}
        e0 = arcs[cf[0]][0]
        cur, f, N, A = e0, cf[0], np.zeros(3), 0.0
        for _ in range(len(cf)):
            a, b = arcs[f]
            nxt = b if a == cur else a
            cr = 0.5 * np.cross(s.X[far[cur]] - s.X[v], s.X[far[nxt]] - s.X[v])
            N += cr
            A += float(np.linalg.norm(cr))
            cur = nxt
            f = next(g for g in cf if g != f and cur in arcs[g])
        num += float(np.linalg.norm(N))
        den += A
    return num / den if den > 0 else 0.0


def _cone_cycle(s, v, ce, cf):
    """Spokes (edge indices) of a cone in the order of its link cycle, and
    the facet between each spoke and the next."""
    absFE = np.where(s.FE >= 0, s.FE, ~s.FE)
    arcs = {f: [int(e) for e in absFE[f] if int(e) in set(ce)] for f in cf}
    cyc, fac = [ce[0]], []
    f = next(g for g in cf if ce[0] in arcs[g])
    while len(fac) < len(cf):
        a, b = arcs[f]
        nxt = b if a == cyc[-1] else a
        fac.append(f)
        if len(fac) == len(cf):
            break
        cyc.append(nxt)
        f = next(g for g in cf if g != f and nxt in arcs[g])
    return cyc, fac


def _merge_cones(s, v, cones):
    """Two broad cones at ``v`` widened into a neck (REF's merge, measured on
    double cones of equal facet counts): each spoke of the first cone is
    paired with the nearest spoke of the second, going round both in the
    same sense; each pair meets at a ring point halfway between their
    midpoints; the cones' facets lose their corners (as in the sphere pop)
    and a fan from the ring's mean closes the neck (the septum; REF 2.70
    puts it even when both insides are one body)."""
    vid = int(s.ids("vertex")[v])
    if len(cones[0][0]) != len(cones[1][0]):
        raise UnsupportedError("popping a vertex where two broad cones of unequal facet counts "
                               "meet", f"vertex {vid}: the Evolver merges them into a neck by "
                               "a rule not implemented")
    _check_star(s, v)
    sp, far, fs = _star(s, v)
    XL, off = _lifted(s, v, sp, far)
    spos = {int(e): j for j, e in enumerate(sp)}
    U = [_cone_cycle(s, v, ce, cf) for ce, cf in cones]
    n = len(U[0][0])
    vec = [np.array([XL[far[spos[e]]] - XL[v] for e in U[k][0]]) for k in range(2)]
    axis = vec[0].mean(axis=0) - vec[1].mean(axis=0)
    # the same rotational sense round the axis for both cycles
    for k in range(2):
        turn = np.cross(vec[k], np.roll(vec[k], -1, axis=0)).sum(axis=0) @ axis
        if turn < 0:
            U[k] = (U[k][0][::-1], U[k][1][::-1][1:] + U[k][1][::-1][:1])
            vec[k] = vec[k][::-1]
    unit = [x / np.linalg.norm(x, axis=1)[:, None] for x in vec]
    best = min(range(n), key=lambda sh: -float(np.sum(unit[0] * np.roll(unit[1], -sh, axis=0))))
    pair_b = [U[1][0][(j + best) % n] for j in range(n)]
    cells = _cells(s, v, sp, fs, XL)
    F = s.F

    def inside(k, c):
        """Whether cell ``c`` lies inside cone k (on the side of its axis)."""
        f, sd = c[0]
        a, b, d = XL[F[f, 0]], XL[F[f, 1]], XL[F[f, 2]]
        return sd * float(np.cross(b - a, d - a) @ vec[k].mean(axis=0)) > 0
    conef = [set(cf) for _, cf in cones]
    caps = [next(i for i, c in enumerate(cells) if all(f in conef[k] for f, _ in c)
                 and inside(k, c)) for k in range(2)]
    # the manual: no septum when both insides are one body; REF 2.70 puts
    # one there too (a double cone whose two insides are one body), as here
    septum = True
    m = len(fs)
    ring_par = [int(U[0][1][j]) for j in range(n)]
    e_par = [int(f) for f in fs] + ring_par + ([ring_par[0]] * n if septum else [])
    f_par = [int(f) for f in fs] + ([ring_par[0]] * n if septum else [])
    t = grow(s, v_from_edge=[int(U[0][0][j]) for j in range(n)] +
             ([int(U[0][0][0])] if septum else []), e_from_facet=e_par, f_from_facet=f_par)
    nv, ne, nf = s.nv, s.ne, s.nf
    R = nv + np.arange(n)
    ring_of = {}
    for j in range(n):
        a, b = U[0][0][j], pair_b[j]
        t.X[R[j]] = XL[v] + 0.25 * (vec[0][j] + (XL[far[spos[b]]] - XL[v]))
        ring_of[a] = ring_of[b] = int(R[j])
    for e in sp:                        # spokes start at their ring point
        t.E[e] = np.where(t.E[e] == v, ring_of[int(e)], t.E[e])
    ring_e = ne + m + np.arange(n)
    ring_idx = {}
    for j in range(n):
        t.E[ring_e[j]] = (R[j], R[(j + 1) % n])
        ring_idx[(int(R[j]), int(R[(j + 1) % n]))] = int(ring_e[j])
        if off is not None:
            t.eattr["wrap"][ring_e[j]] = 0

    def ring_edge(a, b):
        if (a, b) in ring_idx:
            return ring_idx[(a, b)]
        return ~ring_idx[(b, a)]
    spoke_far = {int(far[j]): int(e) for j, e in enumerate(sp)}
    for i, f in enumerate(fs):
        row = [int(x) for x in s.FE[f]]
        vs = [int(x) for x in s.F[f]]
        kv = vs.index(v)
        p, q = vs[(kv + 1) % 3], vs[(kv + 2) % 3]
        rp, rq = ring_of[spoke_far[p]], ring_of[spoke_far[q]]
        e_vp, e_pq, e_qv = row[kv], row[(kv + 1) % 3], row[(kv + 2) % 3]
        # the quad rp p q rq is split along p - rq (REF's neck; the sphere
        # pop uses the other diagonal): (p, q, rq) keeps f, (rp, p, rq) is new
        d = ne + i
        t.E[d] = (p, rq)
        if off is not None:
            t.eattr["wrap"][d] = -off[spos[spoke_far[p]]]
        eq = e_qv if e_qv >= 0 else ~e_qv
        t.FE[f] = (e_pq, eq if t.E[eq, 0] == q else ~eq, ~d)
        t.FE[nf + i] = (e_vp, d, ring_edge(rq, rp))
    if septum:
        c = nv + n
        t.X[c] = t.X[R].mean(axis=0)
        spk = ne + m + n + np.arange(n)
        for j in range(n):
            t.E[spk[j]] = (c, R[j])
            if off is not None:
                t.eattr["wrap"][spk[j]] = 0
        for j in range(n):
            t.FE[nf + m + j] = (spk[j], ring_edge(int(R[j]), int(R[(j + 1) % n])),
                                ~spk[(j + 1) % n])
        if s.bodies.n:
            _septum_bodies(s, t, v, nf + m, n, [cells[c_] for c_ in caps],
                           vec[0].mean(axis=0))
    vkeep = np.ones(t.nv, bool)
    vkeep[v] = False
    return subset(t, t.E, t.FE, vkeep, np.ones(t.ne, bool), np.ones(t.nf, bool))


def _septum_bodies(s, t, v, first, n, caps, up):
    """Body memberships of the septum's facets: it separates the first
    cone's inside (direction ``up`` from ``v``) from the second's."""
    b0, b1 = (_region_body(s, c) for c in caps)
    F = t.F
    rows, cols, vals = [], [], []
    for f in range(first, first + n):
        a, b, d = t.X[F[f, 0]], t.X[F[f, 1]], t.X[F[f, 2]]
        into0 = float(np.cross(b - a, d - a) @ up) > 0
        for body, sg in ((b0, -1 if into0 else 1), (b1, 1 if into0 else -1)):
            if body >= 0:
                rows.append(body)
                cols.append(f)
                vals.append(sg)
    _set_body_columns(t, first, rows, cols, vals)


def _split_cones(s, v):
    """Two cones meeting at ``v``: split them (the second cone, the one
    without ``v``'s lowest-numbered edge, moves to a copy of ``v`` at the
    same place), or refuse the Evolver's merging into a neck."""
    vid = int(s.ids("vertex")[v])
    cones = _cones(s, v)
    if cone_flatness(s, v, cones) > CONE_MERGE:
        return _merge_cones(s, v, cones)
    eid = s.ids("edge")
    cones.sort(key=lambda c: min(eid[e] for e in c[0]))
    move = np.array(cones[1][0], np.int64)
    t = grow(s, v_from_edge=[int(move[0])])
    w = s.nv
    for key, arr in t.vattr.items():
        if key != "id":
            arr[w] = s.vattr[key][v]
    for cid, arr in t.vcon.items():
        arr[w] = s.vcon[cid][v]
    t.X[w] = s.X[v]
    E = t.E.copy()
    E[move] = np.where(E[move] == v, w, E[move])
    t.E = E
    t.__dict__.pop("_topo", None)
    t.__dict__.pop("_corners", None)
    t.topology_version = getattr(t, "topology_version", 0) + 1
    return t


def _lifted(s, v, sp, far):
    """Positions with each far end of a spoke lifted next to ``v`` (the
    torus model), and each spoke's period offset (in cells) from ``v`` to its
    far end (None outside the torus)."""
    if s.periods is None or "wrap" not in s.eattr:
        return s.X, None
    W = s.eattr["wrap"][sp]
    off = np.where((s.E[sp, 0] == v)[:, None], W, -W)
    X = s.X.copy()
    X[far] = s.X[far] + off @ s.periods
    return X, off


def _check_star(s, v):
    for q in s.quantities.values():
        if any(sgn is not None and et in ("edge", "facet") for (_, et, _, sgn) in q.methods):
            raise UnsupportedError("popping a vertex on a surface whose quantities list "
                                   "edges or facets", f"quantity {q.name}")


def prism_kind(s, v, sp, cells):
    """3 or 4 when the link of ``v``, its nodes of degree 2 left out, is the
    graph of a triangular prism or of a cube (the cells then have 3, 3, 4, 4,
    4 or six times 4 triple nodes), else 0.  The Evolver pops these two cones
    its own way (a triangular prism by ``kraynikpopvertex``'s special pop, a
    cube to a square), not by the sphere."""
    val = _edge_valence(s)
    sizes = []
    for c in cells:
        loop = _cell_loop(s, v, sp, c)
        sizes.append(int(np.count_nonzero(val[sp[loop]] == 3)))
    sizes.sort()
    if sizes == [3, 3, 4, 4, 4]:
        return 3
    if sizes == [4] * 6:
        return 4
    return 0


def _pop_one(s, v, kraynik=True):
    """Pop vertex ``v`` (index) by the sphere construction; returns the new
    surface.  Refuses (UnsupportedError) what was not checked against REF."""
    _check_star(s, v)
    vid = int(s.ids("vertex")[v])
    sp, far, fs = _star(s, v)
    X = s.X
    ten = s.fattr["tension"][fs]
    if not np.all(ten == ten[0]):
        raise UnsupportedError("popping a vertex whose facets have unequal tensions",
                               f"vertex {vid}")
    if (far == v).any() or len(set(far.tolist())) != len(far):
        raise UnsupportedError("popping a vertex with a loop or multiple edges",
                               f"vertex {vid}")
    XL, off = _lifted(s, v, sp, far)
    cells = _cells(s, v, sp, fs, XL)
    for c in cells:
        if len({f for f, _ in c}) != len(c) or len(c) < 3:
            raise UnsupportedError("popping a vertex whose regions touch a facet twice",
                                   f"vertex {vid}")
    kind = prism_kind(s, v, sp, cells)
    if kind == 3 and kraynik:
        raise UnsupportedError("popping a vertex whose link is a triangular prism with "
                               "kraynikpopvertex on", f"vertex {vid}: the Evolver's special pop "
                               "of this cone (to an edge, or to a face with pop_to_face) is not "
                               "implemented; kraynikpopvertex off pops it by the sphere")
    if kind == 4:
        raise UnsupportedError("popping a vertex whose link is a cube", f"vertex {vid}: the "
                               "Evolver pops this cone to a square, which is not implemented")
    return _build(s, v, sp, far, fs, cells, XL, off)


def _cell_loop(s, v, sp, c):
    """Spoke positions in order round cell ``c`` (list of (facet, side))."""
    F = s.F
    spoke_of = {}
    for k, e in enumerate(sp):
        spoke_of[int(s.E[e, 0] if s.E[e, 1] == v else s.E[e, 1])] = k
    arcs = []
    for f, _ in c:
        a, b = [spoke_of[int(w)] for w in F[f] if w != v]
        arcs.append((a, b, f))
    loop = [arcs[0][0], arcs[0][1]]
    used = {0}
    while len(used) < len(arcs):
        cur = loop[-1]
        nxt = next(i for i in range(len(arcs)) if i not in used and cur in arcs[i][:2])
        used.add(nxt)
        a, b, _ = arcs[nxt]
        loop.append(b if a == cur else a)
    if loop[-1] != loop[0]:
        raise UnsupportedError("popping a vertex whose regions are not discs",
                               f"vertex {int(s.ids('vertex')[v])}")
    return loop[:-1]


def cell_sizes(s, v, sp, cells, X=None):
    """Solid angle (seen from ``v``) of each cell's polygon of spoke
    midpoints."""
    X = s.X if X is None else X
    W = 0.5 * (X[v] + X[np.where(s.E[sp, 0] == v, s.E[sp, 1], s.E[sp, 0])])
    out = []
    for c in cells:
        loop = _cell_loop(s, v, sp, c)
        P = W[loop] - X[v]
        P = P / np.linalg.norm(P, axis=1)[:, None]
        m = P.mean(axis=0)
        m = m / np.linalg.norm(m)
        tot = 0.0
        for i in range(len(P)):
            a, b = P[i], P[(i + 1) % len(P)]
            num = abs(np.dot(m, np.cross(a, b)))
            den = 1 + m @ a + a @ b + b @ m
            tot += 2 * np.arctan2(num, den)
        out.append(tot)
    return np.array(out)


def _region_body(s, region):
    """The body filling a complement region (list of (facet, side)), or -1:
    a facet's normal side is outside the bodies that list it with +."""
    M = s.bodies.facet_matrix.tocsc()
    found = set()
    for f, side in region:
        col = M[:, f].toarray().ravel()
        bs = np.nonzero(col == -side)[0]
        found.add(int(bs[0]) if len(bs) else -1)
    if len(found) != 1:
        raise UnsupportedError("popping a vertex whose regions are not single bodies")
    return found.pop()


def _cell_bodies(s, t, v, first, keep, big):
    """Body memberships of the cells' new facets (``t``'s facets from
    ``first`` on, built cell by cell in ``keep`` order): each separates its
    cell's region (outside the sphere) from the largest cell's region, which
    now fills the sphere."""
    inner = _region_body(s, big)
    nb, nf = s.bodies.n, t.nf
    F = t.F
    X = t.X
    rows, cols, vals = [], [], []
    k = first
    for c in keep:
        outer = _region_body(s, c)
        n = len(c) - 2 if len(c) <= 4 else len(c)
        for f in range(k, k + n):
            a, b, d = X[F[f, 0]], X[F[f, 1]], X[F[f, 2]]
            nrm = np.cross(b - a, d - a)
            out = float(nrm @ ((a + b + d) / 3 - s.X[v])) > 0      # normal into the cell
            for body, sg in ((outer, -1 if out else 1), (inner, 1 if out else -1)):
                if body >= 0 and body != (inner if body == outer else -2):
                    rows.append(body)
                    cols.append(f)
                    vals.append(sg)
        k += n
    _set_body_columns(t, first, rows, cols, vals)


def _set_body_columns(t, first, rows, cols, vals):
    """Replace the body memberships of ``t``'s facets from ``first`` on."""
    b = t.bodies
    M = b.facet_matrix.tocoo()
    old = M.col < first
    r = np.concatenate([M.row[old], rows]).astype(np.int64)
    cc = np.concatenate([M.col[old], cols]).astype(np.int64)
    vv = np.concatenate([M.data[old], vals]).astype(float)
    b.facet_matrix = sps.csr_matrix((vv, (r, cc)), shape=(b.n, t.nf))
    ob, of, osg = b.occurrences
    ok = of < first
    b.occurrences = (np.concatenate([ob[ok], np.asarray(rows, np.int64)]),
                     np.concatenate([of[ok], np.asarray(cols, np.int64)]),
                     np.concatenate([osg[ok], np.asarray(vals, osg.dtype)]))
    b.volume = None


def _build(s, v, sp, far, fs, cells, XL, off):
    sizes = cell_sizes(s, v, sp, cells, XL)
    big = int(np.argmax(sizes))
    keep = [c for i, c in enumerate(cells) if i != big]
    loops = [_cell_loop(s, v, sp, c) for c in keep]
    centred = [i for i, lp in enumerate(loops) if len(lp) > 4]
    quads = [i for i, lp in enumerate(loops) if len(lp) == 4]
    m, k = len(fs), len(sp)
    # new vertices: w per spoke (edge-born), a centre per centred cell
    # new edges: per facet its arc w_p-w_q and diagonal; per centred cell its spokes
    # new facets: per facet its second half; per cell its triangles
    cell_f = [int(keep[i][0][0]) for i in centred]
    e_par = list(fs) + list(fs) + [int(keep[i][0][0]) for i in quads] + \
        [cell_f[j] for j, i in enumerate(centred) for _ in loops[i]]
    f_tri = []
    for i, lp in enumerate(loops):
        n = len(lp) - 2 if len(lp) <= 4 else len(lp)
        f_tri += [int(keep[i][0][0])] * n
    t = grow(s, v_from_edge=list(sp), v_from_facet=cell_f, e_from_facet=e_par,
             f_from_facet=list(fs) + f_tri)
    nv, ne, nf = s.nv, s.ne, s.nf
    W = nv + np.arange(k)
    C = nv + k + np.arange(len(centred))
    t.X[W] = 0.5 * (XL[v] + XL[far])
    spoke_of = {int(p): j for j, p in enumerate(far)}
    # spokes now start at their w
    for j, e in enumerate(sp):
        if t.E[e, 0] == v:
            t.E[e, 0] = W[j]
        else:
            t.E[e, 1] = W[j]
    arc = ne + np.arange(m)
    diag = ne + m + np.arange(m)
    arc_of = {}
    absFE = np.where(s.FE >= 0, s.FE, ~s.FE)
    for i, f in enumerate(fs):
        row = [int(x) for x in s.FE[f]]
        vs = [int(x) for x in s.F[f]]
        kv = vs.index(v)
        p, q = vs[(kv + 1) % 3], vs[(kv + 2) % 3]
        wp, wq = W[spoke_of[p]], W[spoke_of[q]]
        e_vp, e_pq, e_qv = row[kv], row[(kv + 1) % 3], row[(kv + 2) % 3]
        t.E[arc[i]] = (wq, wp)
        t.E[diag[i]] = (wp, q)
        if off is not None:           # the spokes keep their wraps (w is in v's cell)
            t.eattr["wrap"][arc[i]] = 0
            t.eattr["wrap"][diag[i]] = off[spoke_of[q]]
        # (wp, p, q) keeps f; (q, wq, wp) is new
        t.FE[f] = (e_vp, e_pq, ~diag[i])      # e_vp now runs wp -> p (same sign)
        t.FE[nf + i] = (diag[i], ~e_qv if False else e_qv, arc[i])
        arc_of[int(f)] = (int(arc[i]), int(wq), int(wp))
    # fix the sign of e_qv in the new half: it runs q -> wq
    for i, f in enumerate(fs):
        e = t.FE[nf + i, 1]
        ei = e if e >= 0 else ~e
        a, b = t.E[ei]
        vs = [int(x) for x in s.F[f]]
        kv = vs.index(v)
        q = vs[(kv + 2) % 3]
        t.FE[nf + i, 1] = ei if a == q else ~ei
    # cells
    fpos = nf + m
    epos = ne + 2 * m
    for i, lp in enumerate(loops):
        ws = [W[j] for j in lp]
        # the arc between consecutive loop points
        def arc_between(a, b):
            for f, _ in keep[i]:
                ea, x, y = arc_of[f]
                if (x, y) == (a, b):
                    return ea
                if (x, y) == (b, a):
                    return ~ea
            raise AssertionError
        if len(lp) == 3:
            t.FE[fpos] = [arc_between(ws[j], ws[(j + 1) % 3]) for j in range(3)]
            fpos += 1
            continue
        if len(lp) == 4:
            # the diagonal runs from the arc's tail (in the facet's own
            # orientation) of the cell's facet of lowest id
            fid = s.ids("facet")
            f0 = min((f for f, _ in keep[i]), key=lambda f: fid[f])
            r = ws.index(arc_of[f0][1])
            a, b, c, d = (ws[(r + j) % 4] for j in range(4))
            dg = epos
            epos += 1
            t.E[dg] = (a, c)
            if off is not None:
                t.eattr["wrap"][dg] = 0
            t.FE[fpos] = (arc_between(a, b), arc_between(b, c), ~dg)
            t.FE[fpos + 1] = (dg, arc_between(c, d), arc_between(d, a))
            fpos += 2
            continue
        c = C[centred.index(i)]
        t.X[c] = t.X[ws].mean(axis=0)
        spk = epos + np.arange(len(lp))
        epos += len(lp)
        for j in range(len(lp)):
            t.E[spk[j]] = (c, ws[j])
            if off is not None:
                t.eattr["wrap"][spk[j]] = 0
        for j in range(len(lp)):
            j2 = (j + 1) % len(lp)
            t.FE[fpos] = (spk[j], arc_between(ws[j], ws[j2]), ~spk[j2])
            fpos += 1
    assert fpos == t.nf and epos == t.ne
    if s.bodies.n:
        _cell_bodies(s, t, v, nf + m, keep, cells[big])
    vkeep = np.ones(t.nv, bool)
    vkeep[v] = False
    return subset(t, t.E, t.FE, vkeep, np.ones(t.ne, bool), np.ones(t.nf, bool))


def pop_vertices(s, which=None, kraynik=True):
    """Pop the non-minimal vertices of ``s`` (all, or those in ``which``),
    in id order, each on the surface the previous pops left.

    Returns ``(surface, n)``; ``s`` itself is never modified.
    """
    bad = nonminimal_vertices(s, which)
    if not len(bad):
        return s, 0
    tested, ncomp, triple, high = link_summary(s)
    for b in bad:
        vid = int(s.ids("vertex")[b])
        if high[b]:
            raise UnsupportedError("popping a vertex on an edge with four or more facets",
                                   f"vertex {vid}")
    ids = s.ids("vertex")[bad]
    n = 0
    for vid in ids:
        v = int(np.nonzero(s.ids("vertex") == vid)[0][0])
        s = _split_cones(s, v) if _cone_count(s, v) > 1 else _pop_one(s, v, kraynik)
        n += 1
    return s, n
